// kincal (private): the process's one pool of worker threads. Every parallel loop of the library
// (the identification's rows, the program folders of compensate_backup) runs on it: no thread is
// started per evaluation, and a loop's per-thread scratch is indexed by the slot the pool gives.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>

namespace kincal::detail {

/// The work of one loop: f(begin, end, slot) for the pieces [begin, end) of [0, n); slot is unique
/// among the threads running the loop at once (0 is the caller), below the loop's thread count.
using PieceFunction = std::function<void(std::size_t begin, std::size_t end, std::size_t slot)>;

/// The number of threads a loop may use: the hardware's cores (at least 1), the caller included.
std::size_t pool_threads();

/// Runs f over [0, n) in pieces of `grain` indices (at least 1), handed out in increasing order to at
/// most `max_threads` threads (0: pool_threads(); the caller is one of them) and returns when every
/// piece is done. A piece stops at the first exception it lets out; no piece is handed out after
/// that, and once every running piece is done the exception of the lowest piece is rethrown, so the
/// error is the one a serial loop would meet first. A loop started while another runs (nested, or
/// from a second user thread) runs serially on its caller (slot 0). After fork() the child starts a
/// new pool.
void parallel_pieces(std::size_t n, std::size_t grain, std::size_t max_threads, const PieceFunction& f);

/// The fewest measurement rows worth a thread of their own in the identification's evaluations.
constexpr std::size_t kRowsPerThread = 256;

/// Runs f over [0, n) in one contiguous piece per thread, with at least `at_least` indices a thread
/// (fewer do not pay for the hand-over).
inline void parallel_rows(std::size_t n, std::size_t at_least, const PieceFunction& f) {
  const std::size_t threads = std::min(pool_threads(), n / at_least + 1);
  parallel_pieces(n, (n + threads - 1) / threads, threads, f);
}

}  // namespace kincal::detail
