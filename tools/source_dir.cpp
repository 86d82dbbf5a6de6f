#include "tools/source_dir.h"

namespace rlg::tools {

std::string SourcePath(const std::string& rel) { return std::string(RLG_SOURCE_DIR) + "/" + rel; }

}  // namespace rlg::tools
