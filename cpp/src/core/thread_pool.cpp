// kincal: the process's worker threads (thread_pool.hpp).
#include "thread_pool.hpp"

#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace kincal::detail {

namespace {

class Pool {
 public:
  explicit Pool(std::size_t workers) {
    for (std::size_t i = 0; i < workers; ++i) workers_.emplace_back([this] { work(); });
  }
  // never destroyed (see pool()): its threads wait until the process ends
  Pool(const Pool&) = delete;
  Pool& operator=(const Pool&) = delete;

  std::size_t threads() const { return workers_.size() + 1; }

  void run(std::size_t n, std::size_t grain, std::size_t k, const PieceFunction& f) {
    bool idle = false;
    if (k <= 1 || !busy_.compare_exchange_strong(idle, true)) {  // nested or concurrent: the caller alone
      for (std::size_t b = 0; b < n; b += grain) f(b, std::min(n, b + grain), 0);
      return;
    }
    struct Release {
      std::atomic<bool>& busy;
      ~Release() { busy = false; }
    } release{busy_};
    {
      std::lock_guard<std::mutex> lock(m_);
      f_ = &f;
      n_ = n;
      grain_ = grain;
      next_ = 0;
      wanted_ = k - 1;
      joined_ = 0;
      active_ = k - 1;
      error_ = nullptr;
      error_piece_ = SIZE_MAX;
      ++generation_;
    }
    wake_.notify_all();
    pieces(0);
    std::unique_lock<std::mutex> lock(m_);
    // every piece is handed out: a worker that has not joined yet would find nothing, so it is not
    // waited for (on a short loop the caller would otherwise wait out a sleeping thread's wake-up)
    active_ -= wanted_ - joined_;
    wanted_ = joined_;
    done_.wait(lock, [this] { return active_ == 0; });
    f_ = nullptr;
    if (error_) std::rethrow_exception(error_);
  }

 private:
  void pieces(std::size_t slot) {
    for (std::size_t b = next_.fetch_add(grain_); b < n_; b = next_.fetch_add(grain_)) {
      try {
        (*f_)(b, std::min(n_, b + grain_), slot);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m_);
        if (b < error_piece_) error_piece_ = b, error_ = std::current_exception();
        next_ = n_;  // hand out nothing more
      }
    }
  }

  void work() {
    std::uint64_t seen = 0;
    for (;;) {
      std::size_t slot;
      {
        std::unique_lock<std::mutex> lock(m_);
        wake_.wait(lock, [&] { return generation_ != seen; });
        seen = generation_;
        if (joined_ >= wanted_) continue;  // this loop has its threads
        slot = ++joined_;
      }
      pieces(slot);
      {
        std::lock_guard<std::mutex> lock(m_);
        --active_;
      }
      done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::atomic<bool> busy_{false};  // a loop owns the workers
  std::mutex m_;
  std::condition_variable wake_, done_;
  const PieceFunction* f_ = nullptr;
  std::size_t n_ = 0, grain_ = 1, wanted_ = 0, joined_ = 0, active_ = 0, error_piece_ = SIZE_MAX;
  std::atomic<std::size_t> next_{0};
  std::exception_ptr error_;
  std::uint64_t generation_ = 0;
};

std::size_t hardware_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

std::atomic<Pool*> the_pool{nullptr};
std::mutex create_mutex;

// A forked child has the pool's memory but none of its threads (and maybe a locked mutex): it
// forgets that pool (left as it is) and starts its own on first use.
void forget_pool_in_child() { the_pool.store(nullptr); }

Pool& pool() {
  Pool* p = the_pool.load(std::memory_order_acquire);
  if (p) return *p;
  std::lock_guard<std::mutex> lock(create_mutex);
  p = the_pool.load();
  if (!p) {
    static const bool registered = (pthread_atfork(nullptr, nullptr, forget_pool_in_child), true);
    (void)registered;
    // deliberately never deleted: joining threads during static destruction can deadlock at exit
    p = new Pool(hardware_threads() - 1);
    the_pool.store(p, std::memory_order_release);
  }
  return *p;
}

}  // namespace

std::size_t pool_threads() { return hardware_threads(); }

void parallel_pieces(std::size_t n, std::size_t grain, std::size_t max_threads, const PieceFunction& f) {
  if (n == 0) return;
  grain = std::max<std::size_t>(grain, 1);
  const std::size_t pieces = (n + grain - 1) / grain;
  std::size_t k = std::min(max_threads == 0 ? hardware_threads() : max_threads, pieces);
  if (k <= 1) {
    for (std::size_t b = 0; b < n; b += grain) f(b, std::min(n, b + grain), 0);
    return;
  }
  Pool& p = pool();
  p.run(n, grain, std::min(k, p.threads()), f);
}

}  // namespace kincal::detail
