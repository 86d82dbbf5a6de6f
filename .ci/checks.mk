# The checks .ci/run runs after the Release build, as targets of `make -k -j2 -O -f .ci/checks.mk`:
# make keeps both cores busy, starting the longest checks first (the order of `all`) and each
# as soon as what it needs is built; -O prints each check's output in one piece when it ends; -k
# runs every check even after one fails, and make then fails. How long each takes:
# docs/testing.md, "CI step times".
SHELL := /bin/bash
STEP := bash .ci/step
SAN := RLG_SANITIZE_JOBS=1 RLG_SANITIZE_BUILD_JOBS=1 bash tools/sanitize.sh
CTEST := cd build && ctest --output-on-failure

.PHONY: all confusion sanitizer reference_1s test reference_10s reference_short heldout_10s heldout_60s tsan wheel memcheck bench
all: confusion sanitizer test reference_1s heldout_10s reference_10s heldout_60s reference_short tsan wheel bench memcheck

confusion:        # the 100-case confusion matrix of the blind diagnosis
	$(STEP) "confusion matrix (diagnosis_full)" bash -c '$(CTEST) -L diagnosis_full'
# The sanitizer build (clang ASan + UBSan and the fuzzers, build-san/), then its unit and CLI
# tests, then the fuzzers, in one slot: each starts as soon as the build ends, and a failing test does not stop the fuzzers (as
# separate targets, make would give the build's slot to the next check and run these last).
sanitizer:
	$(STEP) "sanitizer build" env RLG_SANITIZE_ONLY=build $(SAN)
	s=0; $(STEP) "sanitizer unit and CLI tests (sanitize)" env RLG_SANITIZE_ONLY=units $(SAN) || s=$$?; \
	  $(STEP) "fuzzers" env RLG_SANITIZE_ONLY=fuzz $(SAN) || s=$$?; exit $$s
reference_1s:     # the blind cases on the independent generator's 1 s data
	$(STEP) "reference, 1 s" bash -c '$(CTEST) -L reference -R blind_clear_cases_1s'
reference_10s:
	$(STEP) "reference, 10 s" bash -c '$(CTEST) -L reference -R "blind_clear_cases$$"'
test:             # README command 2; ctest -j2 inside fills a core the others leave
	$(STEP) "test command (tools/test.sh)" bash tools/test.sh
heldout_10s:      # the second independent generator's 34 cases (tests/heldout), one process
	$(STEP) "held-out generator, 10 s" bash -c 'export RLG_HELDOUT_JOBS=1; $(CTEST) -L heldout -R blind_10s'
heldout_60s:
	$(STEP) "held-out generator, 60 s" bash -c 'export RLG_HELDOUT_JOBS=1; $(CTEST) -L heldout -R blind_60s'
reference_short:  # the generator's self-tests, the smoke test, the 60 s blind cases
	$(STEP) "reference, self-tests and 60 s" bash -c '$(CTEST) -L reference -E "blind_clear_cases(_1s)?$$"'
# The ThreadSanitizer build (clang TSan, build-tsan/: only the threaded code's unit tests), then
# those tests (label tsan), in one slot.
tsan:
	$(STEP) "tsan build" env RLG_TSAN_ONLY=build RLG_TSAN_BUILD_JOBS=1 bash tools/tsan.sh
	$(STEP) "tsan tests (tsan)" env RLG_TSAN_ONLY=tests RLG_TSAN_JOBS=1 bash tools/tsan.sh
wheel:            # the wheel pip builds (its compiles ccache hits), in a fresh venv, the Python tests against it
	$(STEP) "wheel in a fresh venv (tools/wheel_test.sh)" bash tools/wheel_test.sh
memcheck:
	$(STEP) "memcheck" bash -c '$(CTEST) -L memcheck'
bench:
	$(STEP) "benchmarks, smoke (bench)" bash -c '$(CTEST) -L bench'
