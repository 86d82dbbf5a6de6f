#pragma once
/// The entries of the search table (effect_search.h), one factory per catalog effect, each in
/// the file of its kind: thermal_searches.cpp, sensor_searches.cpp, bias_searches.cpp,
/// mode_hop_search.cpp. Only effect_search.cpp's table calls them.

#include <memory>

#include "diagnosis/catalog/effect_search.h"

namespace rlg::diagnosis::catalog {

std::unique_ptr<const EffectSearch> MissingMassSearch();
std::unique_ptr<const EffectSearch> MissingLinkSearch();
std::unique_ptr<const EffectSearch> PowerDriftSearch();
std::unique_ptr<const EffectSearch> RadiationSearch();
std::unique_ptr<const EffectSearch> SensorLagSearch();
std::unique_ptr<const EffectSearch> SensorOffsetSearch();
std::unique_ptr<const EffectSearch> TemperatureRateSearch();
std::unique_ptr<const EffectSearch> GradientSearch();
std::unique_ptr<const EffectSearch> HysteresisSearch();
std::unique_ptr<const EffectSearch> PlaySearch();
std::unique_ptr<const EffectSearch> ModeHopSearch();

}  // namespace rlg::diagnosis::catalog
