// The paper's Eq. (2) fits, Eq. (3) SSE and the pair ranking.

#include <gtest/gtest.h>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>

#include "model/coefficients_json.h"
#include "model/guo2006.h"
#include "tests/model/guo2006_truth.h"
#include "model/pairs.h"
#include "sim/errors.h"

namespace rlg::model {
namespace {

/// A run that follows Eq. (2) exactly plus white noise of sigma. Temperatures dwell for the
/// B0 window (so B0 is exactly the constant c) and noise starts after it, which makes the
/// model exact and ordinary least squares unbiased with exact standard errors.
sim::Run EquationTwoRun(const std::string& id, double T0, const Eigen::Matrix3d& A, double sigma, uint64_t seed,
                        double hours = 2.0) {
  boost::random::mt19937_64 rng(seed);
  boost::random::normal_distribution<double> normal;
  sim::Run r;
  r.id = id;
  auto& Ti = r.AddColumn("T1");
  auto& Tj = r.AddColumn("T2");
  auto& b = r.AddColumn("bias_dph");
  const Eigen::Vector3d a = A * Eigen::Vector3d(1.0, T0, T0 * T0);
  const double c = 1.0 + 0.01 * T0;
  for (double t = 0.0; t <= hours * 3600.0; t += 1.0) {
    const double s = std::max(0.0, t - 120.0);
    const double ti = T0 + 3.0 * (1.0 - std::exp(-s / 1500.0)) + 0.5 * std::sin(s / 900.0);
    const double tj = ti + 1.2 * (1.0 - std::exp(-s / 400.0));
    const double dT = ti - T0;
    r.t_s.push_back(t);
    Ti.push_back(ti);
    Tj.push_back(tj);
    b.push_back(c + a[0] * dT + a[1] * dT * dT + a[2] * (tj - ti) + (t >= 120.0 ? sigma * normal(rng) : 0.0));
  }
  return r;
}

std::vector<sim::Run> NineAmbients(double sigma) {
  std::vector<sim::Run> runs;
  for (int k = 0; k < 9; ++k) {
    const double T0 = -30.0 + 10.0 * k;
    runs.push_back(EquationTwoRun("run" + std::to_string(k), T0, TrueA(), sigma, 100 + k));
  }
  return runs;
}

std::vector<const sim::Run*> Ptrs(const std::vector<sim::Run>& v) {
  std::vector<const sim::Run*> p;
  for (const auto& r : v) p.push_back(&r);
  return p;
}

/// The message of the E that FitGuo2006 throws on `runs` with `method`; a test failure and ""
/// when it throws nothing.
template <class E>
std::string FitRefusal(const std::vector<sim::Run>& runs, FitOptions::Method method) {
  FitOptions o;
  o.method = method;
  try {
    FitGuo2006(Ptrs(runs), o);
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "FitGuo2006 accepted the data";
  return "";
}

TEST(Guo2006, MethodNamesParseBackAndNothingElseParses) {
  for (const Guo2006Method m : {Guo2006Method::kJoint, Guo2006Method::kTwoStage}) {
    EXPECT_EQ(ParseGuo2006Method(Guo2006MethodName(m)), m);
  }
  EXPECT_STREQ(Guo2006MethodName(Guo2006Method::kJoint), "joint");
  EXPECT_STREQ(Guo2006MethodName(Guo2006Method::kTwoStage), "two_stage");
  EXPECT_FALSE(ParseGuo2006Method("Joint").has_value());
  EXPECT_FALSE(ParseGuo2006Method("").has_value());
}

TEST(Guo2006, JointFitRecoversKnownCoefficientsWithinTheirStandardErrors) {
  const auto runs = NineAmbients(0.05);
  FitOptions o;
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), o);
  const Eigen::Matrix3d A = TrueA();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      // The model is exact and the noise white; the errors come from the scatter of 9 runs, so
      // (A_hat - A) / SE ~ t with about 6 dof: |t| > 6 has probability ~1e-3 per coefficient.
      EXPECT_NEAR(c.A(k, l), A(k, l), 6.0 * c.A_stderr(k, l)) << "A" << k + 1 << l;
      EXPECT_GT(c.A_stderr(k, l), 0.0);
    }
  }
  // Residual RMS is the noise: 65,000 samples estimate sigma to ~0.3 %; 2 % margin.
  EXPECT_NEAR(c.residual_rms_dph, 0.05, 0.02 * 0.05);
  EXPECT_EQ(c.runs.size(), 9u);
  EXPECT_EQ(c.stderr_method, "run_scatter");
  // Satterthwaite dof of a scatter over 9 runs: near 9 - 3 (runs alike) and at most the 3 x 9 - 9
  // values the compressed residuals hold.
  EXPECT_GE(c.stderr_dof.minCoeff(), 3.0);
  EXPECT_LE(c.stderr_dof.maxCoeff(), 18.0);
  EXPECT_DOUBLE_EQ(c.t10_range_C[0], -30.0);
  EXPECT_DOUBLE_EQ(c.t10_range_C[1], 50.0);
}

TEST(Guo2006, TwoStageFitRecoversKnownCoefficients) {
  const auto runs = NineAmbients(0.05);
  FitOptions o;
  o.method = FitOptions::Method::kTwoStage;
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), o);
  const Eigen::Matrix3d A = TrueA();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      // Stage 2 fits 3 coefficients to 9 per-run values: its standard errors have 6 degrees of
      // freedom, so t_6 tails: |t| > 6 has probability ~1e-3 per coefficient.
      EXPECT_NEAR(c.A(k, l), A(k, l), 6.0 * c.A_stderr(k, l)) << "A" << k + 1 << l;
    }
  }
  EXPECT_STREQ(Guo2006MethodName(c.method), "two_stage");
}

TEST(Guo2006, NoiselessDataIsFittedExactly) {
  const auto runs = NineAmbients(0.0);
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), FitOptions{});
  // Round-off only: the scaled problem has condition number ~1e3 and the data are O(1).
  EXPECT_LT((c.A - TrueA()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(c.residual_rms_dph, 1e-10);
}

TEST(Guo2006, SseEqualsAHandComputation) {
  // Two runs of four samples; B0 window 2 s = the first two samples.
  Guo2006Coefficients c;
  c.b0_window_s = 2.0;
  c.A << 0.5, 0.0, 0.0,  //
      0.0, 0.0, 0.0,     //
      1.0, 0.0, 0.0;
  std::vector<sim::Run> runs(2);
  const double T1[2][4] = {{10, 10, 11, 12}, {20, 21, 21, 23}};
  const double T2[2][4] = {{10, 11, 11, 13}, {20, 20, 22, 23}};
  const double B[2][4] = {{1.0, 1.2, 1.9, 2.4}, {0.5, 0.3, 1.6, 1.2}};
  for (int r = 0; r < 2; ++r) {
    runs[r].id = "r" + std::to_string(r);
    auto& a = runs[r].AddColumn("T1");
    auto& b = runs[r].AddColumn("T2");
    auto& y = runs[r].AddColumn("bias_dph");
    for (int k = 0; k < 4; ++k) {
      runs[r].t_s.push_back(k);
      a.push_back(T1[r][k]);
      b.push_back(T2[r][k]);
      y.push_back(B[r][k]);
    }
  }
  // Run 0: B0 = 1.1; yhat = 1.1 + 0.5 dT + (T2 - T1) = 1.1, 2.1, 1.6, 3.1
  //   residuals -0.1, -0.9, 0.3, -0.7 -> SSE = 0.01 + 0.81 + 0.09 + 0.49 = 1.40
  // Run 1: B0 = 0.4; yhat = 0.4, 0.4 + 0.5 - 1 = -0.1, 0.4 + 0.5 + 1 = 1.9, 0.4 + 1.5 + 0 = 1.9
  //   residuals 0.1, 0.4, -0.3, -0.7 -> SSE = 0.01 + 0.16 + 0.09 + 0.49 = 0.75
  EXPECT_NEAR(RunSse(c, runs[0]), 1.40, 1e-12);
  EXPECT_NEAR(RunSse(c, runs[1]), 0.75, 1e-12);
}

TEST(Guo2006, OneAmbientCannotIdentifyTheTi0TermsAndSaysWhich) {
  std::vector<sim::Run> runs;
  for (int k = 0; k < 3; ++k) runs.push_back(EquationTwoRun("r" + std::to_string(k), 20.0, TrueA(), 0.05, k));
  const std::string m = FitRefusal<NumericalError>(runs, FitOptions::Method::kJoint);
  EXPECT_NE(m.find("cannot separate"), std::string::npos) << m;
  for (const char* name : {"A11", "A12", "A21", "A22", "A31", "A32"}) EXPECT_NE(m.find(name), std::string::npos) << m;
  EXPECT_NE(m.find("3 runs at 1 start temperature"), std::string::npos) << m;
  EXPECT_NE(m.find("20.00 °C (r0, r1, r2)"), std::string::npos) << m;
  EXPECT_NE(m.find("3 or more different ambients"), std::string::npos) << m;
}

TEST(Guo2006, TwoAmbientsAreRefusedSayingThreeStartTemperaturesAreNeededAndWhichTheDataHas) {
  // The refusal names the cause (three power-on temperatures needed), not a count of samples.
  std::vector<sim::Run> runs = {EquationTwoRun("a", 0.0, TrueA(), 0.05, 1),
                                EquationTwoRun("b", 40.0, TrueA(), 0.05, 2)};
  for (const auto method : {FitOptions::Method::kJoint, FitOptions::Method::kTwoStage}) {
    const std::string m = FitRefusal<NumericalError>(runs, method);
    EXPECT_NE(m.find("3 or more different start temperatures Ti0"), std::string::npos) << m;
    EXPECT_NE(m.find("2 runs at 2 start temperatures"), std::string::npos) << m;
    EXPECT_NE(m.find("0.00 °C (a); 40.00 °C (b)"), std::string::npos) << m;
    EXPECT_EQ(m.find("samples"), std::string::npos) << m;
  }
}

/// The joint fit without compression: one dense least squares over every sample by
/// column-pivoted QR, and its errors under white noise with B0's error: y_r = X_r A + M_r e_r,
/// M_r = I - 1 u^T (u: 1/n_W on the B0 window), so
///   Cov(A) = sigma² (X^T X)^-1 (sum_r X_r^T M_r M_r^T X_r) (X^T X)^-1,
///   E[SSR] = sigma² (tr(M M^T) - tr((X^T X)^-1 sum_r X_r^T M_r M_r^T X_r)).
struct DenseFit {
  Row9 A;
  Row9 stderr_white;
};
DenseFit DenseJointFit(const std::vector<sim::Run>& runs) {
  Eigen::Index n = 0;
  for (const auto& r : runs) n += static_cast<Eigen::Index>(r.size());
  Eigen::MatrixXd X(n, 9);
  Eigen::VectorXd y(n);
  Eigen::Matrix<double, 9, 9> XtMMtX = Eigen::Matrix<double, 9, 9>::Zero();
  double trace_MMt = 0.0;
  Eigen::Index row = 0;
  for (const sim::Run& run : runs) {
    const auto& Ti = run.Column("T1");
    const auto& Tj = run.Column("T2");
    const double B0 = InitialBias(run, 120.0);
    const auto len = static_cast<Eigen::Index>(run.size());
    Eigen::VectorXd u = Eigen::VectorXd::Zero(len);
    for (Eigen::Index k = 0; k < len; ++k) {
      const auto i = static_cast<size_t>(k);
      X.row(row + k) = Guo2006Row(Ti[i], Tj[i], Ti.front()).transpose();
      y[row + k] = run.Column("bias_dph")[i] - B0;
      if (run.t_s[i] < run.t_s.front() + 120.0) u[k] = 1.0;
    }
    u /= u.sum();
    const Eigen::MatrixXd Xr = X.middleRows(row, len);
    const Eigen::MatrixXd MtX = Xr - u * Xr.colwise().sum();  // M^T X = X - u 1^T X
    XtMMtX += MtX.transpose() * MtX;
    // tr(M M^T) = |M|_F², row i of M being e_i - u: (1 - u_i)² + sum_{j != i} u_j².
    for (Eigen::Index i = 0; i < len; ++i) trace_MMt += std::pow(1.0 - u[i], 2) + u.squaredNorm() - u[i] * u[i];
    row += len;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X);
  const Eigen::VectorXd beta = qr.solve(y);
  // X P = Q R, so (X^T X)^-1 = P R^-1 R^-T P^T.
  const Eigen::Matrix<double, 9, 9> R = qr.matrixR().topRows<9>().triangularView<Eigen::Upper>();
  const Eigen::Matrix<double, 9, 9> PRinv =
      qr.colsPermutation() * R.triangularView<Eigen::Upper>().solve(Eigen::Matrix<double, 9, 9>::Identity());
  const Eigen::Matrix<double, 9, 9> XtX_inv = PRinv * PRinv.transpose();
  const double s2 = (y - X * beta).squaredNorm() / (trace_MMt - (XtX_inv * XtMMtX).trace());
  DenseFit d;
  d.A = beta;
  d.stderr_white = (s2 * XtX_inv * XtMMtX * XtX_inv).diagonal().cwiseSqrt();
  return d;
}

TEST(Guo2006, JointFitEqualsTheDenseLeastSquaresForAnyRunLength) {
  // Runs of 4 (the least the fit takes), 5, 40 samples and 2 h: the per-run QR compression
  // must give the dense problem's coefficients whatever a run's length.
  std::vector<sim::Run> runs;
  const int lengths[] = {4, 5, 40, 7201};
  const double T0s[] = {-10.0, 5.0, 20.0, 35.0};
  for (int r = 0; r < 4; ++r) {
    sim::Run full = EquationTwoRun("r" + std::to_string(r), T0s[r], TrueA(), 0.05, 50 + r);
    if (lengths[r] < 7201) {
      // Keep the first sample and spread the rest over the run, so a short run still spans the
      // B0 window and sees the temperatures move.
      sim::Run cut;
      cut.id = full.id;
      for (const auto& name : full.names) cut.AddColumn(name);
      for (int k = 0; k < lengths[r]; ++k) {
        const size_t i = static_cast<size_t>(k) * (full.size() - 1) / static_cast<size_t>(lengths[r] - 1);
        cut.t_s.push_back(full.t_s[i]);
        for (size_t c = 0; c < full.names.size(); ++c) cut.columns[c].push_back(full.columns[c][i]);
      }
      full = cut;
    }
    runs.push_back(full);
  }
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), FitOptions{});
  const DenseFit d = DenseJointFit(runs);
  for (int j = 0; j < 9; ++j) {
    // Both are backward-stable least squares of a problem with scaled condition ~1e3 (the dense
    // one unscaled, ~1e7): agreement to 1e-7 of the coefficient's standard error is round-off.
    EXPECT_NEAR(c.A(j / 3, j % 3), d.A[j], 1e-7 * d.stderr_white[j]) << "A" << j / 3 + 1 << j % 3;
  }
}

TEST(Guo2006, ThreeRunsGiveWhiteNoiseErrorsWithB0sErrorThatEqualTheDenseFormulaForBothMethods) {
  // Three runs leave no run-to-run scatter: both methods fall back to the within-run residuals
  // under white noise, B0's error included (the stage-2 scatter of three runs has 3 - 3 = 0
  // degrees of freedom: dividing by them would report inf).
  std::vector<sim::Run> runs;
  for (int r = 0; r < 3; ++r) {
    runs.push_back(EquationTwoRun("r" + std::to_string(r), -20.0 + 30.0 * r, TrueA(), 0.05, 70 + r, 0.25));
  }
  const DenseFit d = DenseJointFit(runs);
  for (const auto method : {FitOptions::Method::kJoint, FitOptions::Method::kTwoStage}) {
    FitOptions o;
    o.method = method;
    const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), o);
    EXPECT_EQ(c.stderr_method, "within_run_white");
    EXPECT_EQ(c.stderr_dof, Eigen::Matrix3d::Constant(3.0 * 901.0 - 9.0));  // samples - 9 coefficients
    for (int j = 0; j < 9; ++j) {
      // With 3 runs the nine A_kl are an exact function of the nine per-run a_k, so both
      // methods give the dense fit's coefficients and errors; 1e-6 relative is round-off through
      // condition numbers ~1e3 (compressed, scaled) and ~1e7 (dense, unscaled).
      EXPECT_NEAR(c.A(j / 3, j % 3), d.A[j], 1e-6 * d.stderr_white[j]) << "A" << j / 3 + 1 << j % 3;
      EXPECT_NEAR(c.A_stderr(j / 3, j % 3), d.stderr_white[j], 1e-6 * d.stderr_white[j])
          << "A" << j / 3 + 1 << j % 3;
    }
  }
}

TEST(Guo2006, WhenEveryRunWarmsUpAlikeTheJointRunScatterErrorsEqualTheTwoStageScatter) {
  // Identical temperature curves give every run the same R3: the joint fit is then stage 2's
  // least squares for each k (same regressors), its common 3x3 covariance estimate reduces to
  // the stage-2 scatter, and the Satterthwaite dof to stage 2's m - 3 (a scaled chi-square):
  // closed-form checks of the moment estimator and of the dof.
  std::vector<sim::Run> runs;
  for (int r = 0; r < 6; ++r) {
    runs.push_back(EquationTwoRun("r" + std::to_string(r), -20.0 + 12.0 * r, TrueA(), 0.05, 90 + r));
  }
  FitOptions two;
  two.method = FitOptions::Method::kTwoStage;
  const Guo2006Coefficients j = FitGuo2006(Ptrs(runs), FitOptions{});
  const Guo2006Coefficients t = FitGuo2006(Ptrs(runs), two);
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) {
      // Same estimator by two routes; 1e-8 of a standard error (or of a dof) is round-off.
      EXPECT_NEAR(j.A(k, l), t.A(k, l), 1e-8 * t.A_stderr(k, l)) << "A" << k + 1 << l;
      EXPECT_NEAR(j.A_stderr(k, l), t.A_stderr(k, l), 1e-8 * t.A_stderr(k, l)) << "A" << k + 1 << l;
      EXPECT_EQ(t.stderr_dof(k, l), 3.0);
      EXPECT_NEAR(j.stderr_dof(k, l), 3.0, 1e-8) << "A" << k + 1 << l;
    }
}

TEST(Guo2006, ConfidenceHalfWidthIsStudentsQuantileTimesTheStandardError) {
  Guo2006Coefficients c;
  c.A_stderr.setConstant(2.0);
  c.stderr_dof.setConstant(1e9);
  c.stderr_dof(0, 1) = 6.0;
  const Eigen::Matrix3d hw = c.ConfidenceHalfWidth(0.95);
  // Tabulated t_{0.975, 6} = 2.446912 and the normal 1.959964 (t at 1e9 dof); the tables' 7
  // digits, times the standard error 2.
  EXPECT_NEAR(hw(0, 1), 2.0 * 2.446912, 2e-6);
  EXPECT_NEAR(hw(2, 2), 2.0 * 1.959964, 2e-6);
  EXPECT_THROW(c.ConfidenceHalfWidth(1.0), std::invalid_argument);
  c.stderr_dof(1, 1) = 0.0;  // coefficients read from a file have no error model
  EXPECT_THROW(c.ConfidenceHalfWidth(0.95), std::logic_error);
}

TEST(Guo2006, ARunTooShortToFitIsRefusedNamingItInsteadOfReadingPastItsRows) {
  // A 2-row run that spans the B0 window made the per-run thin QR read a
  // 3x3 corner of a 2x3 matrix; the release build fitted coefficients from memory past it.
  std::vector<sim::Run> runs = NineAmbients(0.05);
  sim::Run tiny;
  tiny.id = "tiny";
  auto& t1 = tiny.AddColumn("T1");
  auto& t2 = tiny.AddColumn("T2");
  auto& b = tiny.AddColumn("bias_dph");
  tiny.t_s = {0.0, 200.0};
  t1 = {20.0, 21.0};
  t2 = {20.0, 22.0};
  b = {0.5, 0.6};
  runs.push_back(tiny);
  for (const auto method : {FitOptions::Method::kJoint, FitOptions::Method::kTwoStage}) {
    const std::string m = FitRefusal<InputError>(runs, method);
    EXPECT_NE(m.find("run 'tiny' has 2 samples"), std::string::npos) << m;
    EXPECT_NE(m.find("at least 4"), std::string::npos) << m;
  }
}

TEST(Guo2006, ShortRunsAndMissingChannelsAreInputErrors) {
  std::vector<sim::Run> runs = NineAmbients(0.05);
  FitOptions o;
  o.pair = {"T1", "T4"};
  EXPECT_THROW(FitGuo2006(Ptrs(runs), o), InputError);
  sim::Run shorty = EquationTwoRun("short", 0.0, TrueA(), 0.05, 1, 0.02);  // 72 s
  try {
    InitialBias(shorty, 120.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shorter than the 120 s B0 window"), std::string::npos) << e.what();
  }
}

TEST(Guo2006, CoefficientsSurviveTheJsonRoundTrip) {
  const auto runs = NineAmbients(0.05);
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), FitOptions{});
  const nlohmann::json j = ToJson(c);
  EXPECT_EQ(j["model"], "guo2006");
  EXPECT_EQ(j["A"].size(), 3u);
  const Guo2006Coefficients back = CoefficientsFromJson(nlohmann::json::parse(j.dump()), "mem");
  EXPECT_EQ(back.A, c.A);  // JSON doubles round-trip exactly (shortest representation)
  EXPECT_EQ(back.pair, c.pair);
  EXPECT_EQ(back.runs, c.runs);
  nlohmann::json broken = j;
  broken.erase("A");
  EXPECT_THROW(CoefficientsFromJson(broken, "mem"), InputError);
}

TEST(Pairs, PaperCombinationsInThePapersOrder) {
  const auto& m = PaperCombinations();
  ASSERT_EQ(m.size(), 6u);
  const std::vector<std::array<std::string, 2>> expected = {
      {"T1", "T2"}, {"T1", "T4"}, {"T2", "T4"}, {"T3", "T2"}, {"T3", "T4"}, {"T4", "T3"}};
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(m[i].name, "M" + std::to_string(i + 1));
    EXPECT_EQ(m[i].pair, expected[i]);
  }
}

TEST(Pairs, AllOrderedPairsOfFourChannelsAreTwelveAndNameTheM) {
  sim::Run r;
  for (const char* n : {"T_amb", "T1", "T2", "T3", "T4", "bias_dph"}) r.AddColumn(n);
  const auto all = AllOrderedPairs(r);
  EXPECT_EQ(all.size(), 12u);
  EXPECT_EQ(all.front().name, "M1");
}

TEST(Pairs, MissingChannelsAreThoseTheCombinationsUseAndTheRunLacks) {
  sim::Run r;
  for (const char* n : {"T_amb", "T1", "T2", "T3", "bias_dph"}) r.AddColumn(n);
  EXPECT_EQ(MissingChannels(r, PaperCombinations()), std::vector<std::string>{"T4"});
  EXPECT_EQ(TemperatureChannels(r), (std::vector<std::string>{"T1", "T2", "T3"}));
  EXPECT_TRUE(MissingChannels(r, AllOrderedPairs(r)).empty());
}

TEST(Pairs, TheGeneratingPairWinsOnDataMadeFromIt) {
  // Data made from the (T1, T2) model; a third channel T3 is a smooth function of time that
  // cannot stand in for the gradient.
  std::vector<sim::Run> runs = NineAmbients(0.02);
  for (auto& r : runs) {
    auto& t3 = r.AddColumn("T3");
    for (double t : r.t_s) t3.push_back(r.Column("T1").front() + 0.5 * (1.0 - std::exp(-t / 5000.0)));
  }
  const std::vector<PairCombination> combos = {{"A", {"T1", "T2"}}, {"B", {"T1", "T3"}}, {"C", {"T3", "T2"}}};
  const auto scores = ScorePairs(Ptrs(runs), combos, FitOptions{});
  EXPECT_EQ(BestPair(scores).combination.name, "A");
  // SSE_ave is the mean of the per-run SSEs (Eq. 3).
  double sum = 0.0;
  for (const auto& pr : scores[0].per_run) sum += pr.second;
  EXPECT_NEAR(scores[0].sse_ave, sum / 9.0, 1e-12);
}

}  // namespace
}  // namespace rlg::model
