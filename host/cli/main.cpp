// Command line: render, diff. (Being written; the subcommands land in the next commits.)
#include <cstdio>
int main() {
  std::fprintf(stderr, "pt: not built yet\n");
  return 1;
}
