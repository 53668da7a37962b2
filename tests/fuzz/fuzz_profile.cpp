// Fuzz target: the profile parser and validator (optics/profile.*), the input's bytes taken as
// the TOML text of a profile file. A profile is refused with ProfileError (one line) or accepted; an
// accepted one must also survive its own serialisation, as profile_to_toml promises.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "optics/profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  nelf::Profile profile;
  try {
    profile = nelf::parse_profile(text, "fuzz.toml");
  } catch (const nelf::ProfileError&) {
    return 0;  // refused with a message: what most inputs must get
  }
  const std::string written = nelf::profile_to_toml(profile);
  try {
    const std::string rewritten = nelf::profile_to_toml(nelf::parse_profile(written, "round trip"));
    if (rewritten != written) {
      std::fprintf(stderr, "profile_to_toml does not round-trip:\n%s\n--- read back as ---\n%s\n", written.c_str(),
                   rewritten.c_str());
      std::abort();
    }
  } catch (const nelf::ProfileError& e) {
    std::fprintf(stderr, "an accepted profile is refused once written back: %s\n%s\n", e.what(), written.c_str());
    std::abort();
  }
  return 0;
}
