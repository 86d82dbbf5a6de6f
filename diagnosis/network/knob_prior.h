#pragma once
/// The baseline knobs' prior: each knob is log-normal about its nominal with the gyro file's
/// relative uncertainty s (log units). Knob i of a model is shifted by
///     z_i = ln(base_i / nominal_i) / s             (prior sds)
/// and the prior's cost on the chi² scale (twice the calibration's cost term) is sum_i z_i².

#include <cstddef>

#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// z_i of knob i of m (KnobCalibration::shift_sigma).
double KnobShiftSigma(const Problem& p, const Model& m, size_t i);

/// sum_i z_i² over the baseline knobs of m: the prior term the calibration minimises, on the
/// chi² scale.
double KnobPriorCost(const Problem& p, const Model& m);

/// Some knob of m beyond kPriorConflictSigma prior sds of its nominal: a knob bent to imitate
/// structure the network lacks. A joint conflict alone (CalibrationSummary::JointConflict:
/// many knobs a little off together, a nominal off by more than it says) is reported, not
/// restarted from: no cause returns a uniformly heavy nominal, and the restarts from its
/// nominal knobs cost refgen's heavy nominal 550 s instead of 8 s on one seed (radiation
/// refits through CVODE from far off).
bool KnobsInConflict(const Problem& p, const Model& m);

}  // namespace rlg::diagnosis
