// Configure-time probe (CMakeLists.txt, ISOFLEX_ARCH=auto): exit 0 when the build machine runs
// x86-64-v3 code (AVX, AVX2, BMI1/2, F16C, FMA, LZCNT, MOVBE). Compiled for the baseline x86-64.
int main() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3") ? 0 : 1;
}
