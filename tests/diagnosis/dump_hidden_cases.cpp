// dump_hidden_cases DIR: writes the blind catalog cases of tests/diagnosis/test_diagnose.cpp
// (`Catalog/HiddenEffect.*`, same effects and seeds) as tidy CSVs DIR/catalog-<effect>.csv, so
// that `rlgtherm diagnose` can be run on exactly the data the tests diagnose
// (tools/regress/record_diagnoses.sh records those answers before and after a refactor).
// dump_hidden_cases DIR EFFECT SEED: one case, DIR/catalog-<effect>-<seed>.csv, e.g. a case of
// the confusion matrix (case k, counted from 1, is drawn from seed base + 100 (k - 1)); its
// truth (target, parameters) is printed.

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>

#include "io/csv.h"
#include "tests/diagnosis/hidden_effects.h"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 4) {
    std::fprintf(stderr, "usage: dump_hidden_cases DIR [EFFECT SEED]\n");
    return 2;
  }
  const std::string dir = argv[1];
  if (argc == 4) {
    const std::string effect = argv[2];
    const uint64_t seed = std::stoull(argv[3]);
    rlg::test::HiddenCase truth;
    const rlg::sim::Trace data = rlg::test::MakeHiddenCase(effect, seed, &truth);
    const std::string path = dir + "/catalog-" + effect + "-" + argv[3] + ".csv";
    std::ofstream out(path);
    rlg::io::WriteTraceCsv(data, out);
    if (!out) {
      std::fprintf(stderr, "dump_hidden_cases: cannot write %s\n", path.c_str());
      return 1;
    }
    std::printf("%s: %s on %s", path.c_str(), effect.c_str(), truth.target.c_str());
    for (const auto& [name, value] : truth.parameters) std::printf(", %s = %.6g", name.c_str(), value);
    std::printf("\n");
    return 0;
  }
  for (const std::string effect :
       {"none", "thermal.missing_mass", "thermal.missing_link", "thermal.power_drift", "thermal.radiation", "sensor.lag",
        "sensor.offset", "bias.temperature_rate", "bias.gradient", "bias.hysteresis", "bias.mode_hop"}) {
    rlg::test::HiddenCase truth;
    // The seed of test_diagnose.cpp's HiddenEffect test.
    const rlg::sim::Trace data = rlg::test::MakeHiddenCase(effect, 1000 + std::hash<std::string>{}(effect) % 1000, &truth);
    std::ofstream out(dir + "/catalog-" + effect + ".csv");
    rlg::io::WriteTraceCsv(data, out);
    if (!out) {
      std::fprintf(stderr, "dump_hidden_cases: cannot write %s/catalog-%s.csv\n", dir.c_str(), effect.c_str());
      return 1;
    }
  }
  return 0;
}
