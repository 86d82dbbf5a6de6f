// Default options of ThreadSanitizer in a RLG_TSAN build (CMakeLists.txt), linked into every
// executable: the runtime calls this before main, and TSAN_OPTIONS still overrides.

extern "C" {

// The first race or lock-order inversion fails the test (exit 66), with both threads' stacks.
const char* __tsan_default_options() { return "halt_on_error=1:second_deadlock_stack=1"; }

}  // extern "C"
