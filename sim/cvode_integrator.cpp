#include "sim/cvode_integrator.h"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <fmt/format.h>

#include "sim/errors.h"

namespace rlg::sim {
namespace {

using VecMap = Eigen::Map<Eigen::VectorXd>;
using ConstVecMap = Eigen::Map<const Eigen::VectorXd>;

std::string FlagName(long flag) {
  char* name = CVodeGetReturnFlagName(flag);  // malloc'd by SUNDIALS 6.4: we must free it
  std::string out = name ? name : "unknown";
  std::free(name);
  return out;
}

}  // namespace

bool IntegratorOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(rtol > 0.0 && rtol < 1.0)) return fail(fmt::format("solver rtol must be in (0, 1), got {}", rtol));
  if (!(atol > 0.0)) return fail(fmt::format("solver atol must be positive, got {}", atol));
  if (max_steps < 1) return fail(fmt::format("solver max_steps must be >= 1, got {}", max_steps));
  if (!(max_step_s >= 0.0)) return fail(fmt::format("solver max_step_s must be >= 0, got {}", max_step_s));
  return true;
}

struct CvodeIntegrator::Impl {
  // Declaration order is destruction order reversed: the context must outlive everything.
  struct ContextDeleter {
    void operator()(SUNContext* c) const {
      SUNContext_Free(c);
      delete c;
    }
  };
  struct VectorDeleter {
    void operator()(_generic_N_Vector* v) const { N_VDestroy(v); }
  };
  struct MatrixDeleter {
    void operator()(_generic_SUNMatrix* m) const { SUNMatDestroy(m); }
  };
  struct SolverDeleter {
    void operator()(_generic_SUNLinearSolver* s) const { SUNLinSolFree(s); }
  };
  struct MemDeleter {
    void operator()(void* m) const { CVodeFree(&m); }
  };

  const OdeSystem& system;
  OdeScratch scratch;  // the system's evaluations' working memory, this integrator's own
  IntegratorOptions options;
  std::unique_ptr<SUNContext, ContextDeleter> ctx;
  std::unique_ptr<_generic_N_Vector, VectorDeleter> y;
  std::unique_ptr<_generic_SUNMatrix, MatrixDeleter> A;
  std::unique_ptr<_generic_SUNLinearSolver, SolverDeleter> LS;
  std::unique_ptr<void, MemDeleter> mem;
  std::exception_ptr pending;  // exception raised inside a callback
  std::string last_message;    // CVODE's own error text
  bool initialised = false;
  double t_stop = NAN;
  bool stepped = false;      // CVode has taken steps since the last (re)initialisation
  double t_last_out = -INFINITY;

  Impl(const OdeSystem& s, const IntegratorOptions& o) : system(s), options(o) {}

  void Check(int flag, const char* call) {
    if (flag < 0) {
      throw NumericalError(fmt::format("{} failed: {} {}", call, FlagName(flag), last_message));
    }
  }

  static int Rhs(realtype t, N_Vector y, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    try {
      const sunindextype n = N_VGetLength(y);
      self->system.CalcTimeDerivatives(t, ConstVecMap(N_VGetArrayPointer(y), n), VecMap(N_VGetArrayPointer(ydot), n),
                                       self->scratch);
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static int Jac(realtype t, N_Vector y, N_Vector /*fy*/, SUNMatrix J, void* user, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user);
    try {
      const sunindextype n = N_VGetLength(y);
      Eigen::Map<Eigen::MatrixXd> jm(SM_DATA_D(J), n, n);  // SUNDenseMatrix is column-major
      self->system.CalcJacobian(t, ConstVecMap(N_VGetArrayPointer(y), n), jm, self->scratch);
      return 0;
    } catch (...) {
      self->pending = std::current_exception();
      return -1;
    }
  }

  static void ErrHandler(int /*code*/, const char* module, const char* function, char* msg, void* user) {
    auto* self = static_cast<Impl*>(user);
    self->last_message = fmt::format("({} {}: {})", module ? module : "", function ? function : "", msg ? msg : "");
  }
};

CvodeIntegrator::CvodeIntegrator(const OdeSystem& system, const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>(system, options)) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError(why);
  auto& m = *impl_;
  const int n = system.size();
  auto* ctx = new SUNContext;
  if (SUNContext_Create(nullptr, ctx) != 0) {
    delete ctx;
    throw NumericalError("SUNContext_Create failed");
  }
  m.ctx.reset(ctx);
  m.y.reset(N_VNew_Serial(n, *ctx));
  m.A.reset(SUNDenseMatrix(n, n, *ctx));
  if (!m.y || !m.A) throw NumericalError("SUNDIALS could not allocate the state vector or matrix");
  m.LS.reset(SUNLinSol_Dense(m.y.get(), m.A.get(), *ctx));
  m.mem.reset(CVodeCreate(CV_BDF, *ctx));
  if (!m.LS || !m.mem) throw NumericalError("CVodeCreate or SUNLinSol_Dense failed");
  m.Check(CVodeSetErrHandlerFn(m.mem.get(), &Impl::ErrHandler, &m), "CVodeSetErrHandlerFn");
}

CvodeIntegrator::~CvodeIntegrator() = default;

void CvodeIntegrator::Reset(double t0, const Eigen::Ref<const Eigen::VectorXd>& x0) {
  auto& m = *impl_;
  VecMap(N_VGetArrayPointer(m.y.get()), m.system.size()) = x0;
  void* mem = m.mem.get();
  if (!m.initialised) {
    m.Check(CVodeInit(mem, &Impl::Rhs, t0, m.y.get()), "CVodeInit");
    m.Check(CVodeSetUserData(mem, &m), "CVodeSetUserData");
    m.Check(CVodeSStolerances(mem, m.options.rtol, m.options.atol), "CVodeSStolerances");
    m.Check(CVodeSetLinearSolver(mem, m.LS.get(), m.A.get()), "CVodeSetLinearSolver");
    m.Check(CVodeSetJacFn(mem, &Impl::Jac), "CVodeSetJacFn");
    m.Check(CVodeSetMaxNumSteps(mem, m.options.max_steps), "CVodeSetMaxNumSteps");
    if (m.options.max_step_s > 0.0) m.Check(CVodeSetMaxStep(mem, m.options.max_step_s), "CVodeSetMaxStep");
    m.initialised = true;
  } else {
    // The step size the integrator had reached is a better first step after the restart than
    // CVODE's own estimate, which starts from a tiny step (this saves most of the start-up
    // steps when measured inputs restart it at every sample); the error test still decides.
    realtype h_last = 0.0;
    if (m.stepped) CVodeGetLastStep(mem, &h_last);
    m.Check(CVodeReInit(mem, t0, m.y.get()), "CVodeReInit");
    m.Check(CVodeSetInitStep(mem, h_last), "CVodeSetInitStep");  // 0 = CVODE's estimate
  }
  m.t_stop = NAN;
  m.stepped = false;
  m.t_last_out = t0;
}

void CvodeIntegrator::AdvanceTo(double t_out, double t_stop, Eigen::Ref<Eigen::VectorXd> x) {
  auto& m = *impl_;
  if (!m.initialised) throw std::logic_error("CvodeIntegrator::AdvanceTo before Reset");
  if (!(t_stop == m.t_stop)) {
    m.Check(CVodeSetStopTime(m.mem.get(), t_stop), "CVodeSetStopTime");
    m.t_stop = t_stop;
  }
  // Inside the last internal step the answer is CVODE's own interpolant: ask for it directly
  // and skip CVode()'s per-call bookkeeping (most of the cost at 1 s outputs).
  realtype t_current = 0.0;
  if (m.stepped && CVodeGetCurrentTime(m.mem.get(), &t_current) == CV_SUCCESS && t_out <= t_current &&
      t_out >= m.t_last_out) {
    VecMap out(N_VGetArrayPointer(m.y.get()), m.system.size());
    N_Vector yv = m.y.get();
    m.Check(CVodeGetDky(m.mem.get(), t_out, 0, yv), "CVodeGetDky");
    m.t_last_out = t_out;
    x = out;
    return;
  }
  realtype t_reached = 0.0;
  m.last_message.clear();
  const int flag = CVode(m.mem.get(), t_out, m.y.get(), &t_reached, CV_NORMAL);
  if (m.pending) {
    std::exception_ptr e = m.pending;
    m.pending = nullptr;
    std::rethrow_exception(e);
  }
  if (flag < 0) {
    realtype t_fail = t_reached;
    CVodeGetCurrentTime(m.mem.get(), &t_fail);
    throw NumericalError(fmt::format("CVODE failed at t = {:.6g} s (integrating towards {:.6g} s): {} {}", t_fail,
                                     t_out, FlagName(flag), m.last_message));
  }
  m.stepped = true;
  m.t_last_out = t_out;
  x = ConstVecMap(N_VGetArrayPointer(m.y.get()), m.system.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) {
      throw NumericalError(fmt::format("CVODE produced a non-finite state at t = {:.6g} s", t_out));
    }
  }
}

long CvodeIntegrator::num_steps() const {
  long n = 0;
  if (impl_->initialised) CVodeGetNumSteps(impl_->mem.get(), &n);
  return n;
}

}  // namespace rlg::sim
