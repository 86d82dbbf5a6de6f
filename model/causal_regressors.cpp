#include "model/causal_regressors.h"

namespace rlg::model {

const char* OffsetName(OffsetRule rule) { return rule == OffsetRule::kFitted ? "fitted" : "power_on"; }

}  // namespace rlg::model
