#pragma once
/// The repository's own files, for the programs built beside it (tests, fuzzers, benchmarks).
/// source_dir.cpp is the one object compiled with the clone's path (RLG_SOURCE_DIR): every other
/// object is then the same bytes in every clone, so ccache hits it from one clone to the next.

#include <string>

namespace rlg::tools {

/// RLG_SOURCE_DIR/rel: a file of the repository this program was built from.
std::string SourcePath(const std::string& rel);

}  // namespace rlg::tools
