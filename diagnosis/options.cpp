#include "diagnosis/options.h"

#include <cmath>
#include <fmt/format.h>

namespace rlg::diagnosis {

bool CalibrationOptions::IsValid(std::string* error) const {
  std::string why;
  if (max_iterations < 1) why = fmt::format("calibration max_iterations must be at least 1 (got {})", max_iterations);
  else if (nuisance_max_iterations < 1)
    why = fmt::format("calibration nuisance_max_iterations must be at least 1 (got {})", nuisance_max_iterations);
  else if (!(function_tolerance > 0.0 && function_tolerance < 1.0))
    why = fmt::format("calibration function_tolerance must be in (0, 1) (got {:g})", function_tolerance);
  else if (!(relative_step > 0.0 && relative_step <= 0.1))
    why = fmt::format("calibration relative_step must be in (0, 0.1] (got {:g})", relative_step);
  if (error) *error = why;
  return why.empty();
}

bool DiagnoseOptions::IsValid(std::string* error) const {
  std::string why;
  if (max_steps < 0) why = fmt::format("max_steps must be 0 or more (got {})", max_steps);
  else if (power && max_steps < 1) why = "power is that of the first search: it needs max_steps of at least 1 (got 0)";
  else if (single_run_pieces < 2) why = fmt::format("single_run_pieces must be at least 2 (got {})", single_run_pieces);
  else if (!(fit_block_s > 0.0 && std::isfinite(fit_block_s)))
    why = fmt::format("fit_block_s must be a positive number of seconds (got {:g})", fit_block_s);
  else if (!(score_block_s >= fit_block_s && std::isfinite(score_block_s)))
    why = fmt::format("score_block_s must be at least fit_block_s = {:g} s (got {:g})", fit_block_s, score_block_s);
  else if (!(min_heldout_ratio >= 1.0))
    why = fmt::format("min_heldout_ratio must be at least 1 (got {:g})", min_heldout_ratio);
  else if (!(min_heldout_gain >= 0.0 && std::isfinite(min_heldout_gain)))
    why = fmt::format("min_heldout_gain must be a finite number, 0 or more (got {:g})", min_heldout_gain);
  else if (!(min_score >= 0.0) || !(tie_score >= 0.0))
    why = fmt::format("min_score and tie_score must be 0 or more (got {:g}, {:g})", min_score, tie_score);
  else if (null_replicates < 0 || thermal_refits < 0)
    why = fmt::format("null_replicates and thermal_refits must be 0 or more (got {}, {})", null_replicates, thermal_refits);
  else if (lookahead < 1)
    why = fmt::format("lookahead must be at least 1 (got {})", lookahead);
  else if (calibration.IsValid(&why))
    unexplained.IsValid(&why);
  if (error) *error = why;
  return why.empty();
}

}  // namespace rlg::diagnosis
