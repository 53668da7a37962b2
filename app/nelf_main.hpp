#pragma once
// nelf's main(): the command line parsed and run; returns the exit status. In the app library, so
// that it is compiled with the commands (one translation unit: CMakeLists.txt says why).
namespace nelf::app {

int nelf_main(int argc, char** argv);

}  // namespace nelf::app
