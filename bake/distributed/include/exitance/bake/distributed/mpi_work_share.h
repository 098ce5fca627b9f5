// bake under mpirun (issue 15, "Scale out"): the MPI side of the runtime's WorkShare
// (runtime/core/work_share.h). MPI is started only when mpirun launched the process (Open MPI's
// OMPI_COMM_WORLD_SIZE or PMIx's PMIX_RANK in the environment): a plain `bake` never touches MPI.
#pragma once
#include <memory>

#include "exitance/runtime/core/work_share.h"

namespace exitance {

class MpiWorkShare final : public WorkShare {
 public:
  // MPI_Init when launched by mpirun, else null. Finalizes MPI when destroyed.
  static std::unique_ptr<MpiWorkShare> start_if_launched_by_mpirun(int& argc, char**& argv);
  ~MpiWorkShare() override;

  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }
  void allgather_ranges(void* data, const std::vector<size_t>& byte_bounds) override;
  void gather_pieces_to_root(const void* own, void* whole, const std::vector<std::vector<BytePiece>>& pieces) override;
  void broadcast(void* data, size_t bytes) override;
  uint64_t sum(uint64_t value) override;

  // Ends the whole job with `code` (a rank that failed: the others must not wait in a collective).
  [[noreturn]] void abort(int code);

 private:
  MpiWorkShare() = default;
  int rank_ = 0, ranks_ = 1;
};

}  // namespace exitance
