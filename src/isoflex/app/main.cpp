// Placeholder entry point; the command line is built in app/.
#include <cstdio>
int main() {
  std::puts("isoflex " ISOFLEX_VERSION);
  return 0;
}
