// Linked into every executable of a SEAM_SANITIZE build (see CMakeLists.txt): LeakSanitizer suppressions for
// one-time allocations that third-party libraries make at load time and never free. They are not leaks of seam's
// code; without the suppression every executable that loads them fails at exit (including GoogleTest discovery).
extern "C" const char* __lsan_default_suppressions();
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libcln.so\n"      // CLN (GiNaC's number library): static initialisers
         "leak:libginac.so\n"    // GiNaC: static initialisers
         "leak:libTK\n";         // OpenCASCADE toolkits (libTK*.so), e.g. IFSelect_Editor in TKXSBase
}

// Do not list the suppressions used at every exit (they are the expected ones above).
extern "C" const char* __lsan_default_options();
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
