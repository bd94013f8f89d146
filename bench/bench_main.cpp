// The micro-benchmarks' main: Google Benchmark's, after one allocator setting.
//
// Benchmarks that grow a plant time growth only, and grow once untimed first so that the timed grows
// reuse memory the process already touched (a page fault costs ~12 us on these VMs, more than ten
// nodes of growth). glibc defeats that reuse on its own: blocks past its mmap threshold are mapped
// fresh on every allocation, and freed memory at the top of the heap goes back to the kernel. So
// here the heap serves every block and is never trimmed. A one-shot `growbench run` still pays its
// page faults, and reports them in its growth phase.
#include <malloc.h>

#include <benchmark/benchmark.h>

int main(int argc, char** argv) {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);  // as an unsigned size: never trim
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
