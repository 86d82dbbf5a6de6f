#pragma once
/// The effect catalog (scenarios/README.md, Effects): one table of Effect objects (sim/effect.h),
/// in catalog order. ApplyEffect, EffectNames and the diagnosis's search table
/// (diagnosis/catalog/effect_search.h) go through it, so an effect is added by one file in
/// sim/effects/, one line in effect_registry.cpp and its entry in diagnosis/catalog/
/// (CONTRIBUTING.md, "Adding an effect").

#include <memory>
#include <string>
#include <vector>

#include "sim/effect.h"

namespace rlg::sim {

/// Every effect, in catalog order (without "none").
const std::vector<std::unique_ptr<const Effect>>& Effects();

/// The effect named `name`, or nullptr.
const Effect* FindEffect(const std::string& name);

/// The effect named `name`; InputError naming the catalog for an unknown name.
const Effect& RequireEffect(const std::string& name);

}  // namespace rlg::sim
