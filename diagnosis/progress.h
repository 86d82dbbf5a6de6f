#pragma once
/// The progress line of a diagnosis: DiagnoseOptions::progress, when set, called with a
/// one-line description as each stage or candidate refit starts, after a prefix that says
/// which search step it belongs to ("step 2: ", or none).

#include <functional>
#include <string>
#include <utility>

namespace rlg::diagnosis {

class Progress {
 public:
  /// `sink` (may be empty) must outlive this.
  explicit Progress(const std::function<void(const std::string&)>& sink, std::string prefix = "")
      : sink_(&sink), prefix_(std::move(prefix)) {}
  void operator()(const std::string& what) const {
    if (*sink_) (*sink_)(prefix_ + what);
  }

 private:
  const std::function<void(const std::string&)>* sink_;
  std::string prefix_;
};

}  // namespace rlg::diagnosis
