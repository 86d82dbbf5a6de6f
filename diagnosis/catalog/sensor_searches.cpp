// The sensor effects' searches (effect_search.h): every channel with data, and where a fit starts.

#include "diagnosis/catalog/searches.h"

namespace rlg::diagnosis::catalog {
namespace {

/// sensor.lag: every channel with data.
class SensorLag final : public EffectSearch {
 public:
  SensorLag() : EffectSearch("sensor.lag", {{"time_constant_s", {5.0}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override { return space.channels; }
};

/// sensor.offset: every channel with data. With the ambient unlogged, offsets on different
/// channels and the ambient trade.
class SensorOffset final : public EffectSearch {
 public:
  SensorOffset() : EffectSearch("sensor.offset", {{"offset_C", {0.01}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override { return space.channels; }
  std::string SeparationAdvice(const std::set<std::string>&, bool ambient_logged) const override {
    if (ambient_logged) return {};
    return "with the ambient unlogged, an offset on one channel is the same model as the opposite offset on the "
           "others and the ambient shifted by it; logging T_amb separates them";
  }
};

}  // namespace

std::unique_ptr<const EffectSearch> SensorLagSearch() { return std::make_unique<SensorLag>(); }
std::unique_ptr<const EffectSearch> SensorOffsetSearch() { return std::make_unique<SensorOffset>(); }

}  // namespace rlg::diagnosis::catalog
