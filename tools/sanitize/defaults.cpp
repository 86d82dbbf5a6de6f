// Default options of the sanitizers in a RLG_SANITIZE build (CMakeLists.txt), linked into every
// executable: the runtimes call these before main, and environment variables still override.

extern "C" {

// A finding aborts with a stack trace; leaks are checked at exit (LeakSanitizer stays on).
const char* __asan_default_options() { return "detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"; }

// Leaks inside third-party libraries we cannot fix are suppressed by library name (lsan.supp).
const char* __lsan_default_options() { return "suppressions=" RLG_LSAN_SUPPRESSIONS; }

const char* __ubsan_default_options() { return "print_stacktrace=1:halt_on_error=1"; }

}  // extern "C"
