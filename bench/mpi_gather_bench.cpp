// bench_mpi_gather (bench/results/mpi.md): what a split Vulkan bake's exchange costs under mpirun.
// Each rank holds its interleaved blocks of `--texels` texels' sums (the estimate's layout:
// TexelAccumulator's 80 bytes, and `--layers` bounce layers of 3 doubles), and rank 0 gathers them
// as LightmapDriver::bake does (gather_interleaved_to_root, one message per run received in place).
// Rank 0 prints the seconds of each round, from a barrier to the end of its receives.
//   mpirun -np 2 build/bench/bench_mpi_gather --texels 1048576 --layers 4 --rounds 5
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "exitance/bake/distributed/mpi_work_share.h"
#include "exitance/runtime/core/estimates.h"

int main(int argc, char** argv) {
  using namespace exitance;
  std::unique_ptr<MpiWorkShare> share = MpiWorkShare::start_if_launched_by_mpirun(argc, argv);
  CLI::App app{"bench_mpi_gather: a split bake's gather of the texels' sums onto rank 0 (run under mpirun)"};
  size_t texels = size_t(1) << 20;
  int layers = 4, rounds = 5;
  app.add_option("--texels", texels, "texels of the whole estimate");
  app.add_option("--layers", layers, "recorded bounce layers (bake's default is 4)")->check(CLI::Range(1, 16));
  app.add_option("--rounds", rounds, "gathers to time")->check(CLI::Range(1, 1000));
  CLI11_PARSE(app, argc, argv);
  if (!share || share->ranks() < 2) {
    std::fprintf(stderr, "bench_mpi_gather: run it under mpirun with 2 or more ranks\n");
    return 2;
  }
  InterleavedSplit split;
  split.items = texels;
  split.ranks = share->ranks();
  const bool root = share->rank() == 0;
  // As bake holds them: the whole arrays on rank 0 (touched before), the rank's own texels packed elsewhere.
  const size_t held = root ? texels : split.count_of(share->rank());
  std::vector<TexelAccumulator> sums(held);
  std::vector<double> bounces(held * size_t(layers) * 3, 1.0);
  std::vector<double> seconds;
  for (int round = 0; round < rounds; ++round) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto start = std::chrono::steady_clock::now();
    gather_interleaved_to_root(*share, sums.data(), 1, split);
    for (int k = 0; k < layers; ++k) gather_interleaved_to_root(*share, bounces.data() + size_t(k) * held * 3, 3, split);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  if (root) {
    const double bytes = double(texels - split.count_of(0)) * double(sizeof(TexelAccumulator) + size_t(layers) * 24);
    std::printf("ranks %d texels %zu layers %d received_MB %.1f seconds", share->ranks(), texels, layers, bytes / 1e6);
    for (double s : seconds) std::printf(" %.4f", s);
    std::sort(seconds.begin(), seconds.end());
    std::printf(" median %.4f GB_per_s %.2f\n", seconds[seconds.size() / 2], bytes / seconds[seconds.size() / 2] / 1e9);
  }
  return 0;
}
