"""ns per 4-wide double division and square root on this machine: the floor of the shell
kernels' plane-stress returns (docs/performance.md, "where its floor is").

    python bench/divider.py

Compiles a loop of 8 independent chains of 4-wide divisions (then square roots) with the
kernels' flags through cffi and prints the processor time per instruction, median of 5
runs: the throughput the returns' divisions and square roots can reach, not their latency.
"""

import statistics
import tempfile
import time

import cffi

SOURCE = """
typedef double vec __attribute__((vector_size(32)));
double chains(long n, int kind)
{
  vec a[8], acc[8];
  const vec one = {1.0, 1.0, 1.0, 1.0};
  for (int i = 0; i < 8; ++i)
  {
    a[i] = (vec){1.1 + i, 1.2 + i, 1.3 + i, 1.4 + i};
    acc[i] = a[i] - a[i];
  }
  for (long k = 0; k < n; ++k)
    for (int i = 0; i < 8; ++i)
    {
      vec r;
      if (kind == 0)
        r = one / a[i];
      else
        for (int l = 0; l < 4; ++l)
          r[l] = __builtin_sqrt(a[i][l]);
      acc[i] += r;
      a[i] += 1e-9;
    }
  double sum = 0.0;
  for (int i = 0; i < 8; ++i)
    sum += acc[i][0] + acc[i][1] + acc[i][2] + acc[i][3];
  return sum;
}
"""
N = 5_000_000


def main():
    ffi = cffi.FFI()
    ffi.cdef("double chains(long n, int kind);")
    ffi.set_source("_rwall_divider", SOURCE,
                   extra_compile_args=["-O3", "-march=native", "-fno-math-errno"])  # fmt: skip
    with tempfile.TemporaryDirectory() as work:
        import importlib.util

        path = ffi.compile(tmpdir=work)
        spec = importlib.util.spec_from_file_location("_rwall_divider", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        for kind, name in enumerate(("division", "square root")):
            times = []
            for _ in range(5):
                start = time.process_time()
                module.lib.chains(N, kind)
                times.append((time.process_time() - start) / (8 * N) * 1e9)
            print(f"4-wide {name}: {statistics.median(times):.2f} ns per instruction")


if __name__ == "__main__":
    main()
