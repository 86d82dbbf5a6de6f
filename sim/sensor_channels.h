#pragma once
/// Which of a gyro's sensor channels a simulation makes (sim/simulator.h).

#include <algorithm>
#include <string>
#include <vector>

namespace rlg::sim {

/// The sensor channels a simulation makes: every one of the gyro's (`only` empty), or those of
/// them named in `only`. Each channel's noise draws from its own substream (sim/noise.h), so a
/// channel is the same bytes whichever others are made: a caller that reads two channels of
/// many runs (a population suite, validation/suite.h) leaves the others' draws and columns out.
struct SensorChannels {
  std::vector<std::string> only;
  bool Makes(const std::string& channel) const {
    return only.empty() || std::find(only.begin(), only.end(), channel) != only.end();
  }
};

}  // namespace rlg::sim
