#include "bake/thread_communicator.h"

#include <barrier>
#include <cstring>
#include <stdexcept>

namespace transgi::bake {

namespace {

// One slot per rank; every collective is: write your slot, wait for all,
// read every slot, wait for all (so no slot is overwritten while read).
struct Exchange {
  explicit Exchange(int n) : slots(static_cast<std::size_t>(n)), arrived(n) {}
  std::vector<std::vector<std::byte>> slots;
  std::barrier<> arrived;
};

class ThreadCommunicator final : public Communicator {
 public:
  ThreadCommunicator(std::shared_ptr<Exchange> x, int rank) : x_(std::move(x)), rank_(rank) {}
  [[nodiscard]] int rank() const override { return rank_; }
  [[nodiscard]] int size() const override { return static_cast<int>(x_->slots.size()); }
  void sum(std::span<float> v) override { sum_in_tree_order(v); }
  void sum(std::span<double> v) override { sum_in_tree_order(v); }

  std::vector<std::vector<std::byte>> all_gather(std::span<const std::byte> mine) override {
    x_->slots[static_cast<std::size_t>(rank_)].assign(mine.begin(), mine.end());
    count_sent(mine.size());
    x_->arrived.arrive_and_wait();
    std::vector<std::vector<std::byte>> all = x_->slots;
    x_->arrived.arrive_and_wait();
    return all;
  }

 private:
  // Every rank adds the same values in the same order, so every rank gets
  // the same bits: Communicator::sum's tree where the rank count is a power
  // of two, rank order otherwise.
  template <class T>
  void sum_in_tree_order(std::span<T> v) {
    const auto all = all_gather(std::as_bytes(std::span<const T>(v.data(), v.size())));
    std::vector<std::vector<T>> parts(all.size(), std::vector<T>(v.size()));
    for (std::size_t r = 0; r < all.size(); ++r) {
      if (all[r].size() != v.size_bytes()) throw std::logic_error("thread communicator: ranks summed spans of different sizes");
      std::memcpy(parts[r].data(), all[r].data(), all[r].size());
    }
    const std::size_t n = parts.size();
    const auto add = [&](std::size_t into, std::size_t from) {
      for (std::size_t i = 0; i < v.size(); ++i) parts[into][i] += parts[from][i];
    };
    if ((n & (n - 1)) == 0) {
      for_each_tree_pair(static_cast<int>(n), 1, [&](int into, int from) {
        add(static_cast<std::size_t>(into), static_cast<std::size_t>(from));
      });
    } else {
      for (std::size_t r = 1; r < n; ++r) add(0, r);
    }
    std::copy(parts[0].begin(), parts[0].end(), v.begin());
  }

  std::shared_ptr<Exchange> x_;
  int rank_;
};

}  // namespace

std::vector<std::unique_ptr<Communicator>> make_thread_group(int size) {
  if (size < 1) throw std::invalid_argument("make_thread_group: size must be at least 1");
  auto x = std::make_shared<Exchange>(size);
  std::vector<std::unique_ptr<Communicator>> group;
  for (int r = 0; r < size; ++r) group.push_back(std::make_unique<ThreadCommunicator>(x, r));
  return group;
}

}  // namespace transgi::bake
