#pragma once
/// R of the Householder QR of a tall matrix A (n x P, n >> P) whose rows arrive one at a time,
/// without storing A: a TSQR (tall-skinny QR; Demmel et al., "Communication-optimal parallel
/// and sequential QR and LU factorizations", 2012). Every kChunk rows are reduced to a P x P
/// upper-triangular R of their own by P Householder reflections, and the chunks' R's are combined
/// pairwise, as in pairwise summation: the R of two stacked R's, [R1; R2], is the R of their
/// rows together. A binary counter of partial R's (one per level: 2^l chunks) keeps the depth of
/// the combinations log2(chunks), so the rounding errors grow as in one QR of the whole matrix,
/// not with the number of chunks: on 7,201 rows of 6 columns the errors of R were 0.4-0.5 of
/// Eigen's QR of the whole matrix (a chain, R updated by every chunk in turn, was 1.1-3x less
/// accurate than Eigen's). Only orthogonal transformations, as a QR of A all at once: the normal
/// equations A^T A would square the condition number. The chunk (64 rows, 3 KB) stays in L1
/// cache; a QR of the whole n x P matrix passes over all of it (n x P doubles) once per column:
/// 3-4x the time (Reduce's 7,201 x 6 in model/guo2006.cpp).
///
/// Only R's first K rows when asked for (K < P): reflections K..P-1 are then not applied. Row j
/// of R is set by reflection j, which involves only rows with a nonzero in column j, and rows
/// K.. of any partial R are zero in columns 0..K-1: they take no part in reflections 0..K-1, so
/// the first K rows are the same without them.
///
/// R is unique up to the signs of its rows when A has full column rank: it then equals the R
/// of Eigen::HouseholderQR of A with the same row signs flipped, up to round-off (tests/model/
/// test_streaming_qr.cpp). The signs are Householder's (R(j,j) takes the opposite sign of the
/// pivot it reflects): callers that need fixed signs normalize them.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "sim/simd.h"

namespace rlg::model {

template <int P, int K = P>
class StreamingQr {
  static_assert(0 < K && K <= P);

 public:
  /// Rows reduced at a time: enough to amortize the reflections' set-up (one square root and
  /// division per column) and the combination with the partial R's, few enough to stay in L1.
  static constexpr int kChunk = 64;
  using RowVector = Eigen::Matrix<double, 1, P>;
  using MatrixR = Eigen::Matrix<double, K, P>;  ///< R's first K rows

  /// The next row of A.
  void Add(const RowVector& row) {
    chunk_.row(rows_) = row;
    if (++rows_ == kChunk) {
      Push(ChunkR(chunk_, rows_));
      rows_ = 0;
    }
  }

  /// R's first K rows for the rows so far (upper triangular; zero rows where fewer than K rows
  /// were added).
  MatrixR R() const {
    MatrixR r = MatrixR::Zero();
    if (rows_ > 0) {
      Chunk partial = chunk_;
      r = ChunkR(partial, rows_);
    }
    // The partial R's from the most recent (fewest rows) up: as a final carry of the counter.
    for (auto level = levels_.rbegin(); level != levels_.rend(); ++level) r = Combine(*level, r);
    return r;
  }

 private:
  using Chunk = Eigen::Matrix<double, kChunk, P>;  // column-major: the reflections run down columns

  /// [R; rows] -> [R'; rows'] by K Householder reflections, R' upper triangular and rows' zero
  /// in columns 0..K-1. Reflection j involves row j of R and the rows only, as R is zero below
  /// its diagonal (Golub & Van Loan, 5.2.1). `rows` is overwritten. On x86-64 the loops run in
  /// AVX2 where the machine has it (sim/simd.h): the same operations in the same order, so the
  /// same bytes.
  template <int M>
  static void Annihilate(MatrixR& R, Eigen::Matrix<double, M, P>& rows) {
#if defined(RLG_AVX2_DISPATCH)
    if (sim::UseAvx2()) return AnnihilateAvx2<M>(R, rows);
#endif
    AnnihilateLoop<M>(R, rows);
  }
#if defined(RLG_AVX2_DISPATCH)
  template <int M>
  RLG_AVX2 static void AnnihilateAvx2(MatrixR& R, Eigen::Matrix<double, M, P>& rows) {
    AnnihilateLoop<M>(R, rows);
  }
#endif

  /// a^T b over M values: four partial sums, lane l taking the values l, l + 4, ..., added as
  /// (s0 + s1) + (s2 + s3), so that the sum is the same bytes in vectors of two or of four.
  template <int M>
  [[gnu::always_inline]] static double Dot(const double* a, const double* b) {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    int i = 0;
    for (; i + 4 <= M; i += 4) {
      s0 += a[i] * b[i];
      s1 += a[i + 1] * b[i + 1];
      s2 += a[i + 2] * b[i + 2];
      s3 += a[i + 3] * b[i + 3];
    }
    for (; i < M; ++i) s0 += a[i] * b[i];
    return (s0 + s1) + (s2 + s3);
  }

  template <int M>
  [[gnu::always_inline]] static void AnnihilateLoop(MatrixR& R, Eigen::Matrix<double, M, P>& rows) {
    double* const a = rows.data();  // column-major: column k at a + k M
    for (int j = 0; j < K; ++j) {
      // The reflection that zeroes column j of the rows against R(j,j), in Eigen's
      // makeHouseholder convention: v = [R(j,j) - beta; u], beta = -sign(R(j,j)) |[R(j,j); u]|,
      // and no reflection when the rows' column is already zero (as Eigen, below the smallest
      // normal number).
      const double* const u = a + j * M;
      const double c0 = R(j, j);
      const double tail = Dot<M>(u, u);
      if (tail <= std::numeric_limits<double>::min()) continue;
      double beta = std::sqrt(c0 * c0 + tail);
      if (c0 >= 0.0) beta = -beta;
      // H a = a - v (v^T a) / (v^T v) with v^T v = 2 beta (beta - c0): per column k > j,
      // d = (c0 - beta) R(j,k) + u^T a_k, f = d / (beta (beta - c0)).
      const double s = c0 - beta;
      const double inv_half_vtv = 1.0 / (beta * (beta - c0));
      for (int k = j + 1; k < P; ++k) {
        double* const ak = a + k * M;
        const double f = (s * R(j, k) + Dot<M>(u, ak)) * inv_half_vtv;
        R(j, k) -= f * s;
        for (int i = 0; i < M; ++i) ak[i] -= f * u[i];
      }
      R(j, j) = beta;
    }
  }

  /// R of the first `used` rows of `chunk`. The unused rows are zeroed: a zero row changes no
  /// sum of squares or dot product (it adds exact zeros), so R is what the used rows alone give.
  static MatrixR ChunkR(Chunk& chunk, int used) {
    chunk.bottomRows(kChunk - used).setZero();
    MatrixR r = MatrixR::Zero();
    Annihilate(r, chunk);
    return r;
  }

  /// R of [upper; lower], both upper triangular (first K rows).
  static MatrixR Combine(MatrixR upper, MatrixR lower) {
    Annihilate(upper, lower);
    return upper;
  }

  /// One more chunk's R into the binary counter: levels_[l] holds the R of 2^l chunks when
  /// bit l of chunks_ is set (levels_ lists the set bits, most significant first). Like
  /// incrementing the count: the R's of the set low bits are combined into the carry.
  void Push(MatrixR r) {
    for (uint64_t c = chunks_; c & 1u; c >>= 1) {
      r = Combine(levels_.back(), r);
      levels_.pop_back();
    }
    levels_.push_back(r);
    ++chunks_;
  }

  Chunk chunk_;
  int rows_ = 0;
  uint64_t chunks_ = 0;
  std::vector<MatrixR> levels_;
};

}  // namespace rlg::model
