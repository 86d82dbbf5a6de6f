#pragma once
/// The repository's own files, for the programs built beside it (tests, fuzzers, benchmarks).
/// source_dir.cpp is the one object of theirs compiled with the clone's path (RLG_SOURCE_DIR):
/// the others are then the same bytes in every clone, and ccache hits them from one to the next.

#include <string>

namespace rlg::tools {

/// RLG_SOURCE_DIR/rel: a file of the repository this program was built from.
std::string SourcePath(const std::string& rel);

}  // namespace rlg::tools
