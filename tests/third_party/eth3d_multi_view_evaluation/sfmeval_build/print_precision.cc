// Added by sfmeval (not part of the ETH3D tool): the tool prints its results with std::cout's
// default precision, 6 significant digits. scripts/build-eth3d-tool.sh compiles the tool's
// unmodified src/main.cc with -Dmain=eth3d_main and links this file, which sets 9 significant
// digits (enough to print every float exactly) and then runs the tool's main.
#include <iostream>

int eth3d_main(int argc, char** argv);

int main(int argc, char** argv) {
  std::cout.precision(9);
  return eth3d_main(argc, argv);
}
