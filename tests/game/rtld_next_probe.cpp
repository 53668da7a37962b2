// nelf-rtld-next-probe: prints the file of the next dlsym after this program's own scope
// (dlsym(RTLD_NEXT, "dlsym")). Under the quad-buffer interposer (LD_PRELOAD) that is the
// interposer itself, as for any preloaded library: dlsym(RTLD_NEXT, …) keeps meaning "after the
// caller" for the game's code although dlsym is interposed.
#include <dlfcn.h>

#include <cstdio>

int main() {
  Dl_info info{};
  void* next = dlsym(RTLD_NEXT, "dlsym");
  if (!next || !dladdr(next, &info) || !info.dli_fname) return 1;
  std::puts(info.dli_fname);
  return 0;
}
