#include "cli/bake_processes.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#if TRANSGI_WITH_MPI
#include <mpi.h>

#include <climits>
#include <cstring>
#include <vector>
#endif

namespace transgi::cli {

namespace {

// What the common launchers set in the processes they start: Open MPI's
// mpirun, MPICH's hydra and Slurm's PMI-2 (PMI_*), PMIx (srun --mpi=pmix).
bool started_by_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_RANK", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(name)) return true;
  return false;
}

#if !TRANSGI_WITH_MPI
// The job's size where the launcher says it in the environment, else 1.
int launcher_world_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  return 1;
}
#endif

#if TRANSGI_WITH_MPI

void check(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string("bake: ") + call + " failed: " + std::string(text, static_cast<std::size_t>(length)));
}

// MPI_COMM_WORLD. Calls may come from any one thread at a time (the bake runs
// inside the job system), hence MPI_THREAD_SERIALIZED.
class MpiCommunicator final : public bake::Communicator {
 public:
  MpiCommunicator() {
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
    if (provided < MPI_THREAD_SERIALIZED) {
      MPI_Finalize();
      throw std::runtime_error("bake: this MPI library cannot be called from a worker thread (MPI_THREAD_SERIALIZED)");
    }
    // Errors come back as codes, to be thrown with their text.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm local;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
    MPI_Comm_size(local, &local_size_);
    MPI_Comm_free(&local);
  }
  ~MpiCommunicator() override { MPI_Finalize(); }
  [[nodiscard]] int rank() const override { return rank_; }
  [[nodiscard]] int size() const override { return size_; }
  [[nodiscard]] int local_size() const { return local_size_; }

  void sum(std::span<float> v) override { tree_sum(v, MPI_FLOAT); }
  void sum(std::span<double> v) override { tree_sum(v, MPI_DOUBLE); }

  std::vector<std::vector<std::byte>> all_gather(std::span<const std::byte> mine) override {
    if (mine.size() > static_cast<std::size_t>(INT_MAX)) throw std::runtime_error("bake: an exchange of over 2 GB");
    const int count = static_cast<int>(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size_)), offsets(static_cast<std::size_t>(size_));
    check(MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
    long long total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[static_cast<std::size_t>(r)] = static_cast<int>(total);
      total += counts[static_cast<std::size_t>(r)];
    }
    if (total > INT_MAX) throw std::runtime_error("bake: an exchange of over 2 GB");
    std::vector<std::byte> all(static_cast<std::size_t>(total));
    check(MPI_Allgatherv(mine.data(), count, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, MPI_COMM_WORLD),
          "MPI_Allgatherv");
    count_sent(sizeof(int) + mine.size());
    std::vector<std::vector<std::byte>> out(static_cast<std::size_t>(size_));
    for (std::size_t r = 0; r < out.size(); ++r)
      out[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
    return out;
  }

 private:
  // Recursive doubling at distances N/2, N/4, ..., 1: after the step at
  // distance d, ranks r and r ^ d hold the same sum of their two partial
  // sums, so every rank ends with the tree's sum (Communicator::sum). It
  // sends log2(N) times the values, where a ring all-reduce sends about
  // twice; for the decoder's gradients that is 175 KB a level.
  template <class T>
  void tree_sum(std::span<T> v, MPI_Datatype type) {
    if ((size_ & (size_ - 1)) != 0) {
      reduce(v.data(), v.size(), type, sizeof(T));
      return;
    }
    std::vector<T> other(v.size());
    for (int d = size_ / 2; d >= 1; d /= 2) {
      const int partner = rank_ ^ d;
      for (std::size_t at = 0; at < v.size();) {
        const std::size_t chunk = std::min<std::size_t>(v.size() - at, INT_MAX / 2);
        check(MPI_Sendrecv(v.data() + at, static_cast<int>(chunk), type, partner, d, other.data() + at, static_cast<int>(chunk),
                           type, partner, d, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
              "MPI_Sendrecv");
        at += chunk;
      }
      for (std::size_t i = 0; i < v.size(); ++i) v[i] += other[i];
      count_sent(v.size_bytes());
    }
  }

  void reduce(void* data, std::size_t n, MPI_Datatype type, std::size_t bytes_each) {
    auto* p = static_cast<char*>(data);
    for (std::size_t at = 0; at < n;) {
      const std::size_t chunk = std::min<std::size_t>(n - at, INT_MAX / 2);
      check(MPI_Allreduce(MPI_IN_PLACE, p + at * bytes_each, static_cast<int>(chunk), type, MPI_SUM, MPI_COMM_WORLD),
            "MPI_Allreduce");
      at += chunk;
    }
    count_sent(n * bytes_each);
  }

  int rank_ = 0, size_ = 1, local_size_ = 1;
};

#endif

}  // namespace

BakeProcesses join_bake_processes() {
  BakeProcesses p;
  if (!started_by_launcher()) return p;
#if TRANSGI_WITH_MPI
  auto mpi = std::make_shared<MpiCommunicator>();
  p.comm = mpi.get();
  p.ranks_on_this_machine = mpi->local_size();
  p.owner = mpi;
  return p;
#else
  if (launcher_world_size() <= 1) return p;
  throw std::runtime_error("bake: started by an MPI launcher as " + std::to_string(launcher_world_size()) +
                           " processes, but this transgi was built without MPI; install libopenmpi-dev and "
                           "reconfigure (TRANSGI_WITH_MPI=ON), or run one process");
#endif
}

void abort_bake_processes(const BakeProcesses& p, int code) {
#if TRANSGI_WITH_MPI
  if (p.comm->size() > 1) MPI_Abort(MPI_COMM_WORLD, code);
#else
  (void)p;
  (void)code;
#endif
}

std::string mpi_description() {
#if TRANSGI_WITH_MPI
  char version[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(version, &length);
  std::string v(version, static_cast<std::size_t>(length));
  if (const auto comma = v.find(','); comma != std::string::npos) v.resize(comma);
  return "MPI (" + v + ")";
#else
  return "no MPI in this build";
#endif
}

}  // namespace transgi::cli
