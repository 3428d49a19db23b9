#pragma once
// The processes that bake one model together (docs/bake.md, "Baking on many
// machines"). A bake is written against this interface; the single-process
// bake gets `solo()`, `mpirun -n N transgi bake` an MPI communicator (the CLI
// links it when the build has MPI), and tests an in-process group of threads.
//
// Every call is collective: every rank makes the same calls in the same order,
// as in MPI. Results are identical on every rank, so state that every rank
// updates from them (the model, the optimiser's moments) stays replicated.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace transgi::bake {

class Communicator {
 public:
  virtual ~Communicator() = default;
  [[nodiscard]] virtual int rank() const = 0;
  [[nodiscard]] virtual int size() const = 0;

  // In-place element-wise sums over the ranks. Where the rank count N is a
  // power of two the sums are a fixed binary tree over the ranks, whatever
  // the transport: rank r's value plus rank r + N/2's first, then those
  // partial sums at distance N/4, ..., 1 (bake/trainer.h relies on it: its
  // steps are the one process's, bit for bit). Otherwise in an order the
  // transport chooses, the same on every rank.
  virtual void sum(std::span<float> values) = 0;
  virtual void sum(std::span<double> values) = 0;
  // Every rank's bytes, in rank order, on every rank (the ranks may send
  // different sizes).
  [[nodiscard]] virtual std::vector<std::vector<std::byte>> all_gather(std::span<const std::byte> mine) = 0;

  // Bytes this rank has handed to the transport so far (what it sent, as the
  // payload sizes of its calls; the transport's own algorithm may move more).
  [[nodiscard]] std::uint64_t bytes_sent() const { return bytes_sent_; }

 protected:
  void count_sent(std::size_t bytes) { bytes_sent_ += bytes; }

 private:
  std::uint64_t bytes_sent_ = 0;
};

// One process alone: sums are the values themselves, nothing is sent.
Communicator& solo();

// The order of Communicator::sum's tree over `count` values (a power of
// two): visit(v, v + d), value v taking value v + d, for d = count / 2, ...,
// down to `lowest`, and v < d at each d. With lowest = 1 value 0 ends with
// the sum. The trainer walks the same tree over its gradient blocks.
template <class Visit>
void for_each_tree_pair(int count, int lowest, Visit visit) {
  for (int d = count / 2; d >= lowest && d >= 1; d /= 2)
    for (int v = 0; v < d; ++v) visit(v, v + d);
}

// Every rank's value of a plain type, in rank order, on every rank.
template <class T>
  requires std::is_trivially_copyable_v<T>
std::vector<T> gather_each(Communicator& comm, const T& mine) {
  const auto all = comm.all_gather(std::as_bytes(std::span(&mine, 1)));
  std::vector<T> out(all.size());
  for (std::size_t r = 0; r < all.size(); ++r) {
    if (all[r].size() != sizeof(T)) throw std::runtime_error("bake: a rank sent a value of the wrong size");
    std::memcpy(&out[r], all[r].data(), sizeof(T));
  }
  return out;
}

}  // namespace transgi::bake
