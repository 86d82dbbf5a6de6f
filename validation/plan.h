#pragma once
/// The calibration-protocol planner (`rlgtherm plan`, docs/plan.md): for each candidate protocol
/// of a plan (validation/plan_spec.h), every gyro is calibrated on the candidate's chamber runs,
/// fitted with the plan's model and compensated on the service conditions, as a production
/// line would, before any chamber is booked.
///
/// Gyro i is the population's gyro i (sim/population.h: drawn from the plan's seed and i), or
/// the nominal gyro with seed GyroSeed(seed, i) when the plan has no [population]. A run is
/// simulated with gyro i's seed on a stream made from its conditions (FNV-1a of
/// ChamberRun::Conditions, calibration and service apart): equal conditions give equal data,
/// so candidates sharing a soak see the same soak (common random numbers: differences between
/// candidates are differences of protocol, not of noise), and each gyro simulates each run once
/// for every candidate that uses it.
///
/// A gyro's score under a candidate is its worst service condition:
///
///   score_i = max_s |mean of the compensated bias in service run s|      (°/h)
///   stability_i = max_s sigma of the compensated bias' 100 s means      (°/h, 1 sigma)
///
/// and the candidate's predictions are over gyros: the median, the p95 (numpy's linear
/// percentile, as populations) and the worst score, the 90 % distribution-free interval of the
/// p95 from the order statistics (validation/order_statistics.h), the median and p95 of the
/// stability, and per service run the median and p95 of |bias after|. Chamber hours: the sum
/// over the candidate's runs of settling and run length (plan_spec.h).
///
/// A candidate meets the target when its interval's upper end is at or below it ("yes"), fails
/// it when the lower end is above ("no"), and is "undecided" otherwise (more gyros would tell).
/// The recommendation is the cheapest candidate that meets it (ties: lower p95, then name), or
/// none, with the reason. The Pareto front: the candidates no other beats on both chamber hours
/// and p95 (at least as good on both, better on one).
///
/// The analytic screen (validation/plan_screen.h) is computed first for every candidate, from
/// the nominal gyro without noise; [screen] keep = K simulates only the K candidates with the
/// smallest screened p95. A candidate the model cannot be fitted on (Eq. (2) on a single
/// power-on, which fixes T10) is reported with the fit's reason and no numbers.
///
/// --verify N: N further gyros, drawn from a seed derived from the plan's (VerifySeed: none of
/// them is a gyro of the prediction), through the recommended candidate; its realised p95 and
/// interval beside the predicted ones: inconsistent when the two intervals do not overlap,
/// consistent when they overlap and both are bounded on both sides, and undecided when they
/// overlap but one is open (fewer than 59 gyros leave the p95's open above, and an interval
/// open above overlaps any prediction under its lower end: no evidence either way).
///
/// Results do not depend on the number of threads: gyro i's numbers are computed alone and
/// stored at index i.
///
/// This header is the planner's face; each concept has its own:
///   validation/plan_spec.h     the plan file and the built-in candidates
///   validation/plan_planner.h  the planner: draw, screen, run gyros, simulate, conclude
///   validation/plan_result.h   what it concludes: distributions, meets, verdict, recommendation
///   validation/plan_shard.h    shards of a plan on machines apart, and their merge
///   validation/plan_report.h   `plan --json`, the text report and the one-line answer
///   validation/plan_screen.h   the analytic screen

#include "validation/plan_planner.h"
#include "validation/plan_report.h"
#include "validation/plan_result.h"
#include "validation/plan_shard.h"
#include "validation/plan_spec.h"
