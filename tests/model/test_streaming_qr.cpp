// The streaming QR (model/streaming_qr.h) against Eigen's Householder QR of the whole matrix: the
// same R, up to the signs of its rows and round-off, on random tall matrices of every chunk
// boundary, badly scaled columns, and fewer rows than columns.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <limits>

#include "model/streaming_qr.h"

namespace rlg::model {
namespace {

constexpr int kP = 6;  // the columns of Eq. (2)'s reduction, [F y 1 u]
using MatrixA = Eigen::Matrix<double, Eigen::Dynamic, kP>;

/// Gaussian n x 6 with column j scaled by scales[j].
MatrixA RandomTall(Eigen::Index n, const Eigen::Matrix<double, 1, kP>& scales, uint64_t seed) {
  boost::random::mt19937_64 rng(seed);
  boost::random::normal_distribution<double> normal;
  MatrixA A(n, kP);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int j = 0; j < kP; ++j) A(i, j) = normal(rng) * scales[j];
  return A;
}

template <int K = kP>
Eigen::Matrix<double, K, kP> StreamedR(const MatrixA& A) {
  StreamingQr<kP, K> qr;
  for (Eigen::Index i = 0; i < A.rows(); ++i) qr.Add(A.row(i));
  return qr.R();
}

/// The first `rows` rows of R with their signs set so that the diagonal is >= 0: R is unique
/// so for a matrix of full column rank.
template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, kP> PositiveDiagonal(const Eigen::Matrix<Scalar, Eigen::Dynamic, kP>& R) {
  Eigen::Matrix<Scalar, Eigen::Dynamic, kP> out = R;
  for (Eigen::Index i = 0; i < R.rows(); ++i)
    if (R(i, i) < 0) out.row(i) *= -1;
  return out;
}

/// Eigen's R of A (its first min(n, 6) rows) in `Scalar`, diagonal >= 0.
template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, kP> EigenR(const MatrixA& A) {
  const Eigen::Matrix<Scalar, Eigen::Dynamic, kP> As = A.cast<Scalar>();
  const Eigen::HouseholderQR<Eigen::Matrix<Scalar, Eigen::Dynamic, kP>> qr(As);
  const Eigen::Index rows = std::min<Eigen::Index>(A.rows(), kP);
  Eigen::Matrix<Scalar, Eigen::Dynamic, kP> R = qr.matrixQR().topRows(rows).template triangularView<Eigen::Upper>();
  return PositiveDiagonal<Scalar>(R);
}

/// max over columns j of |R1(:,j) - R2(:,j)| / |A(:,j)|: Householder QR's backward error is
/// bounded column by column (Higham, Accuracy and Stability, Thm 19.4), so a column's error
/// scales with that column's norm, not with the largest column's.
double ColumnwiseDifference(const Eigen::MatrixXd& R1, const Eigen::MatrixXd& R2, const MatrixA& A) {
  double worst = 0.0;
  for (int j = 0; j < kP; ++j) worst = std::max(worst, (R1.col(j) - R2.col(j)).norm() / A.col(j).norm());
  return worst;
}

/// 2-norm condition number of A with its columns scaled to unit norm (the condition that governs
/// the column-wise error of R; scaling the columns does not change Householder's rounding errors
/// relative to each column). Of its first n columns when n < 6: they alone decide Q.
double ScaledCondition(const MatrixA& A) {
  const Eigen::Index k = std::min<Eigen::Index>(A.rows(), kP);
  const Eigen::MatrixXd As = A.leftCols(k) * A.leftCols(k).colwise().norm().cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(As);
  return svd.singularValues()[0] / svd.singularValues()[k - 1];
}

/// The tolerance on the difference of two R's of A, each from a backward stable QR: each is the
/// exact R of A + dA with |dA(:,j)| <~ c u sqrt(n) |A(:,j)| (the observed growth of the rounding
/// errors of sums of n terms; the worst-case bound grows with n p instead), and R moves by at
/// most ~sqrt(2) cond(A) times the relative perturbation (first-order perturbation bound of the
/// QR factor, Sun 1991); the two factorizations' errors add: 2 sqrt(2) c u sqrt(n) cond. c = 8
/// is a margin for the constants of P reflections per row and log2(chunks) combinations: the
/// differences seen were ~0.1 u sqrt(n) cond, so a wrong sign or a lost row (an O(1) change)
/// fails by many orders of magnitude.
double Tolerance(const MatrixA& A) {
  const double u = std::numeric_limits<double>::epsilon() / 2.0;
  return 2.0 * std::sqrt(2.0) * 8.0 * u * std::sqrt(static_cast<double>(A.rows())) * ScaledCondition(A);
}

TEST(StreamingQr, GivesEigensROnRandomTallMatrices) {
  const Eigen::Matrix<double, 1, kP> unit = Eigen::Matrix<double, 1, kP>::Ones();
  // Around the chunk boundaries (64 rows: one, two, three chunks, where the counter carries), and
  // a run's 7,201 samples.
  static_assert(StreamingQr<kP>::kChunk == 64);
  for (const Eigen::Index n : {6, 7, 63, 64, 65, 127, 128, 129, 192, 193, 1000, 7201}) {
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      const MatrixA A = RandomTall(n, unit, seed);
      const Eigen::MatrixXd R = PositiveDiagonal<double>(StreamedR(A));
      EXPECT_LE(ColumnwiseDifference(R, EigenR<double>(A), A), Tolerance(A)) << "n = " << n << ", seed " << seed;
    }
  }
}

TEST(StreamingQr, FirstRowsOnlyAreThoseOfTheWholeR) {
  // K = 4 of 6 rows, as Reduce asks: reflections 4 and 5 left out, the same first four rows (to
  // the bit: the reflections 0..3 see the same numbers), around chunk boundaries.
  for (const Eigen::Index n : {4, 63, 64, 65, 129, 7201}) {
    const MatrixA A = RandomTall(n, Eigen::Matrix<double, 1, kP>::Ones(), 11);
    const Eigen::Matrix<double, kP, kP> whole = StreamedR(A);
    EXPECT_EQ(StreamedR<4>(A), whole.topRows<4>()) << "n = " << n;
  }
}

TEST(StreamingQr, GivesEigensROnBadlyScaledNearlyDependentColumns) {
  // As Reduce's [dT, dT², Tj - Ti, y, 1, u]: columns 1e-6 ... 1e4 apart, and column 1 nearly a
  // multiple of column 0 (dT² and dT over a warm-up): a scaled condition number ~1e4.
  const Eigen::Matrix<double, 1, kP> scales{1.0, 1e4, 1e-2, 1e-3, 1.0, 1e-6};
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    MatrixA A = RandomTall(7201, scales, seed);
    A.col(1) = 1e4 * A.col(0) + 1e-4 * A.col(1);
    const Eigen::MatrixXd R = PositiveDiagonal<double>(StreamedR(A));
    EXPECT_GT(ScaledCondition(A), 1e3);  // the case is what it says
    EXPECT_LE(ColumnwiseDifference(R, EigenR<double>(A), A), Tolerance(A)) << "seed " << seed;
  }
}

TEST(StreamingQr, IsAsAccurateAsEigensQrOfTheWholeMatrix) {
  // Against Eigen's QR in long double (64-bit significand: its own error ~2^11 times smaller,
  // a reference exact for the purpose): the streamed R's error is at most Eigen's in double.
  // Columns with a mean, as Reduce's (dT² and the constant 1): Eigen's long sums then lose
  // most. Over 40 such matrices the streamed errors were 0.4-0.55 of Eigen's, worst and mean,
  // when this test was written (the pairwise combination's log2 depth against Eigen's sums
  // over all rows).
  const Eigen::Matrix<double, 1, kP> scales{1.0, 30.0, 0.1, 0.01, 1.0, 1e-3};
  double streamed = 0.0, whole = 0.0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    MatrixA A = RandomTall(7201, scales, seed);
    A.rowwise() += 3.0 * scales;
    const Eigen::MatrixXd exact = EigenR<long double>(A).cast<double>();
    streamed = std::max(streamed, ColumnwiseDifference(PositiveDiagonal<double>(StreamedR(A)), exact, A));
    whole = std::max(whole, ColumnwiseDifference(EigenR<double>(A), exact, A));
  }
  EXPECT_GT(whole, 0.0);  // the reference does see double's rounding
  EXPECT_LE(streamed, whole);
}

TEST(StreamingQr, FewerRowsThanColumnsLeavesTheLowerRowsZero) {
  // A run of 4 samples (Reduce's minimum): R's first 4 rows are Eigen's 4 x 6, rows 4, 5 zero.
  const MatrixA A = RandomTall(4, Eigen::Matrix<double, 1, kP>::Ones(), 7);
  const Eigen::Matrix<double, kP, kP> R = StreamedR(A);
  const Eigen::MatrixXd top = PositiveDiagonal<double>(Eigen::MatrixXd(R.topRows(4)));
  EXPECT_LE(ColumnwiseDifference(top, EigenR<double>(A), A), Tolerance(A));
  // Rows 4, 5 are zero but for the round-off the four reflections leave in the chunk's columns
  // 4, 5 (mathematically zero: four rows of rank 4 are spanned by the first four columns).
  EXPECT_LE(ColumnwiseDifference(R.bottomRows(2), Eigen::MatrixXd::Zero(2, kP), A), Tolerance(A));
}

TEST(StreamingQr, RowsOfZerosChangeNothing) {
  // A zero row adds exact zeros to every sum of the reflections: the same R to the bit, which
  // is what lets a partial last chunk be padded with zeros (here 50 rows in their chunk, then
  // a chunk of zeros and part of another).
  const MatrixA A = RandomTall(50, Eigen::Matrix<double, 1, kP>::Ones(), 3);
  MatrixA padded = MatrixA::Zero(150, kP);
  padded.topRows(50) = A;
  StreamingQr<kP> qr;
  for (Eigen::Index i = 0; i < A.rows(); ++i) qr.Add(A.row(i));
  const Eigen::Matrix<double, kP, kP> R = qr.R();
  EXPECT_EQ(StreamedR(padded), R);
}

}  // namespace
}  // namespace rlg::model
