#pragma once
/// Stage 6 of a diagnosis, acceptance: what taking a significant candidate of a step (the
/// leader, statistics/rank.h, or a rival tied with it that is worth more one step ahead:
/// DiagnoseOptions::lookahead) does to the model.
///
///  - a thermal cause (kThermal): its refitted model, recalibrated with every knob and the
///    effect's reported parameters (FitThermal on the fit runs, then the held-out runs'
///    nuisances with them fixed); the step records its parameters, held-out RMS after, and the
///    knobs it moved by at least one prior sd or that were or are beyond kPriorConflictSigma;
///  - a bias cause (kBias): its columns join the bias regression and the effect joins the model
///    with its fitted parameters (the thermal knobs stay); the step records the held-out bias
///    RMS after and the stability ratio of the compensated bias,
///        sd(score-block means of the held-out residual before) / sd(after).

#include <vector>

#include "diagnosis/network/bias_design.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

struct Accepted {
  DiagnosisStep step;               ///< the step given, completed
  Model model;                      ///< the extended model
  std::vector<Extra> bias_columns;  ///< every accepted bias column, this one's included
};

/// `step` (its accepted candidate, before, ties and notes set) accepting the thermal candidate
/// whose refitted model is `refitted`, from the model `current` (bias_columns: the accepted
/// ones so far, kept).
Accepted AcceptThermal(const Problem& p, const Model& current, const Model& refitted,
                       const std::vector<double>& channel_var, const std::vector<Extra>& bias_columns,
                       DiagnosisStep step);

/// `step` accepting the bias candidate with columns `columns`, from the model `current` (pred:
/// its prediction on every run) and the accepted bias columns so far.
Accepted AcceptBias(const Problem& p, const Model& current, const std::vector<Prediction>& pred,
                    const std::vector<Extra>& bias_columns, const std::vector<Extra>& columns, DiagnosisStep step);

}  // namespace rlg::diagnosis
