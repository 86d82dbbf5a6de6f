#pragma once
/// The thermal null bootstrap (docs/diagnosis.md; the thermal twin of network/bias_null.h): the
/// residuals a model leaves on data it made itself, screened with the data (network/thermal_search.h)
/// to set the score a thermal candidate must reach.
///
/// Each replicate holds every channel's white noise (WhiteNoiseSd of the run's column, per fit
/// block) and, for a noisy logged ambient, the error the curve through it carries: the ambient
/// logged again as the model's curve plus white noise of the column's own level
/// (NoiseAtEveryPoint), smoothed as the data's was (LoggedAmbient), and the model driven by
/// both curves. That error is slow (a knot's value holds for a whole segment) and every node
/// feels it, so white-noise scoring underrates it most: on refgen's nulls the residuals' power
/// at 3000 s was 2-3x the white level, and thermal candidates took it up on 8 of 60 nulls.
/// A replicate's score is the best candidate's screening gain less k ln n, as a refit is
/// scored; the threshold is max(min_score, the largest).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// options.null_replicates residual vectors (columns) of model m (pred: its prediction), in
/// the thermal search's flattened order (fit runs, their sensors, their fit blocks), in
/// channel-noise units (channel_var, °C²). Replicate b of run r draws from sim::Rng(0x7e5a0000
/// + b, r), apart from the bias bootstrap's seeds.
Eigen::MatrixXd NullThermalReplicates(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                                      const std::vector<double>& channel_var);

/// What the report says of a thermal null bootstrap.
std::string ThermalNullNote(const Problem& p, const NullBootstrap& null);

}  // namespace rlg::diagnosis
