#include "exitance/bake/distributed/mpi_work_share.h"

#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <stdexcept>

namespace exitance {
namespace {

// MPI counts are ints: exchanges go in rounds of at most this many bytes per rank.
constexpr size_t kLargestPiece = size_t(1) << 30;

void check(int status, const char* call) {
  if (status != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + call + " failed");
}

}  // namespace

std::unique_ptr<MpiWorkShare> MpiWorkShare::start_if_launched_by_mpirun(int& argc, char**& argv) {
  if (!std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMIX_RANK")) return nullptr;
  // Only the main thread calls MPI (the TBB workers never do).
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  std::unique_ptr<MpiWorkShare> share(new MpiWorkShare);
  MPI_Comm_rank(MPI_COMM_WORLD, &share->rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &share->ranks_);
  return share;
}

MpiWorkShare::~MpiWorkShare() { MPI_Finalize(); }

void MpiWorkShare::allgather_ranges(void* data, const std::vector<size_t>& byte_bounds) {
  const size_t parts = size_t(ranks_);
  if (byte_bounds.size() != parts + 1) throw std::logic_error("allgather_ranges: one range per rank expected");
  size_t rounds = 0;
  for (size_t r = 0; r < parts; ++r)
    rounds = std::max(rounds, (byte_bounds[r + 1] - byte_bounds[r] + kLargestPiece - 1) / kLargestPiece);
  std::vector<int> counts(parts), displacements(parts);
  for (size_t round = 0; round < rounds; ++round) {
    // This round's piece of each range; displacements relative to the lowest piece's start.
    const size_t base = byte_bounds[0] + std::min(round * kLargestPiece, byte_bounds[1] - byte_bounds[0]);
    for (size_t r = 0; r < parts; ++r) {
      const size_t length = byte_bounds[r + 1] - byte_bounds[r];
      const size_t begin = std::min(round * kLargestPiece, length);
      counts[r] = int(std::min(kLargestPiece, length - begin));
      const size_t offset = byte_bounds[r] + begin - base;
      if (offset > size_t(INT_MAX)) throw std::runtime_error("MPI: exchange over 2 GiB apart");
      displacements[r] = int(offset);
    }
    check(MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, static_cast<char*>(data) + base, counts.data(),
                         displacements.data(), MPI_BYTE, MPI_COMM_WORLD),
          "MPI_Allgatherv");
  }
}

void MpiWorkShare::gather_pieces_to_root(const void* own, void* whole, const std::vector<std::vector<BytePiece>>& pieces) {
  if (pieces.size() != size_t(ranks_)) throw std::logic_error("gather_pieces_to_root: one list of pieces per rank expected");
  // Point to point, one message per piece of at most kLargestPiece (MPI counts are ints), received
  // in place on rank 0; messages between two ranks match in order (same tag). Requests are waited
  // for in batches, which bounds their number (a run of 1024 texels is a piece: ~10 k per array
  // at 10 M texels).
  constexpr int kTag = 15;
  constexpr size_t kBatch = 1024;
  std::vector<MPI_Request> requests;
  auto post = [&](int status, const char* call) {
    check(status, call);
    if (requests.size() >= kBatch) {
      check(MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
      requests.clear();
    }
  };
  if (rank_ == 0) {
    for (size_t r = 1; r < pieces.size(); ++r)
      for (const BytePiece& p : pieces[r])
        for (size_t done = 0; done < p.size; done += kLargestPiece) {
          requests.emplace_back();
          post(MPI_Irecv(static_cast<char*>(whole) + p.offset + done, int(std::min(kLargestPiece, p.size - done)), MPI_BYTE,
                         int(r), kTag, MPI_COMM_WORLD, &requests.back()),
               "MPI_Irecv");
        }
  } else {
    const char* from = static_cast<const char*>(own);
    for (const BytePiece& p : pieces[size_t(rank_)])
      for (size_t done = 0; done < p.size; done += kLargestPiece) {
        const size_t count = std::min(kLargestPiece, p.size - done);
        requests.emplace_back();
        // MPI 3 takes a const buffer; the cast is for MPI 2 headers.
        post(MPI_Isend(const_cast<char*>(from), int(count), MPI_BYTE, 0, kTag, MPI_COMM_WORLD, &requests.back()), "MPI_Isend");
        from += count;
      }
  }
  check(MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
}

void MpiWorkShare::broadcast(void* data, size_t bytes) {
  if (bytes > size_t(INT_MAX)) throw std::logic_error("broadcast: too large");
  check(MPI_Bcast(data, int(bytes), MPI_BYTE, 0, MPI_COMM_WORLD), "MPI_Bcast");
}

uint64_t MpiWorkShare::sum(uint64_t value) {
  uint64_t total = 0;
  check(MPI_Allreduce(&value, &total, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD), "MPI_Allreduce");
  return total;
}

void MpiWorkShare::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

}  // namespace exitance
