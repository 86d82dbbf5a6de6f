#include "diagnosis/candidate.h"

namespace rlg::diagnosis {

const char* KindName(CandidateKind kind) {
  switch (kind) {
    case CandidateKind::kThermal: return "thermal";
    case CandidateKind::kThermalScreened: return "thermal (screened)";
    case CandidateKind::kThermalNoEffect: return "thermal (no effect)";
    case CandidateKind::kBias: return "bias";
  }
  return "";
}

bool IsThermal(CandidateKind kind) { return kind != CandidateKind::kBias; }

}  // namespace rlg::diagnosis
