// nelf: shows stereo content on near-eye light field displays. See README.md.
#include "app/nelf_main.hpp"

int main(int argc, char** argv) { return nelf::app::nelf_main(argc, argv); }
