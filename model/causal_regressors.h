#pragma once
/// The one interface of the compensation model family (Eq. (2), model/guo2006_regressors.h; the
/// polynomials with their terms, model/poly_model.h): a model is a list of regressors computed
/// causally, sample by sample, from a run's temperature channels and time, and an offset rule:
///
///   fitted offset:     B      = beta . g(t, T)          (a constant regressor among g)
///   power-on offset:   B - B0 = beta . (g(t, T) - G0)    (B0: the mean bias over the first
///                                                        b0_window_s seconds of the run; G0
///                                                        the mean of g over the same samples,
///                                                        or 0 for Eq. (2), whose regressors
///                                                        are its own: ReferredToB0Window)
///
/// B in °/h. The fit (model/linear_fit.h) stacks g of every training sample into one linear
/// least squares; the compensator (model/linear_compensator.h) evaluates the same g at each
/// sample as it comes, so fit and compensation share one piece of code per model.

#include <memory>
#include <string>
#include <vector>

namespace rlg::model {

enum class OffsetRule {
  kFitted,   ///< an absolute bias: a constant is one of the regressors
  kPowerOn,  ///< the bias minus B0, its mean over the first b0_window_s of the run
};

/// "fitted" / "power_on", as the coefficient file and the command line spell them.
const char* OffsetName(OffsetRule rule);

class CausalRegressors {
 public:
  virtual ~CausalRegressors() = default;
  /// The temperature channels Next reads, in the order it reads them.
  virtual const std::vector<std::string>& channels() const = 0;
  /// One name per regressor (the coefficient names of the model's file).
  virtual const std::vector<std::string>& names() const = 0;
  virtual OffsetRule offset() const = 0;
  /// The B0 window (s) of a power-on offset; 0 for a fitted one.
  virtual double b0_window_s() const = 0;
  /// Forgets the run: the next sample is a power-on.
  virtual void Reset() = 0;
  /// The regressors of one sample (`row` has names().size() entries); `T` holds the
  /// temperatures of channels() in that order. Samples in time order.
  virtual void Next(double t_s, const double* T, double* row) = 0;
  /// A fresh copy at power-on.
  virtual std::unique_ptr<CausalRegressors> Clone() const = 0;
  /// A power-on model whose regressors are referred to their mean over the B0 window, as the
  /// bias is to B0 (the polynomial models); false for a fitted offset and for Eq. (2).
  virtual bool ReferredToB0Window() const { return false; }
  /// True when the last sample lay outside the temperature range the model was fitted on (a
  /// polynomial is then held at the range's edge).
  virtual bool OutsideFittedRange() const { return false; }
  /// True when the model extrapolates beyond that range rather than holding at its edge, so
  /// that its value there is its prediction (cross-validation scores it there too).
  virtual bool Extrapolates() const { return false; }
};

}  // namespace rlg::model
