// kincal: the gain of the D-optimal campaign design (kincal plan): how much a candidate
// configuration's rows add to log det of the information matrix.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kincal {

/// For each candidate idx[k] of J (n blocks of `rows` rows by `cols` columns, row-major), the gain
/// of adding its rows J_i to an information matrix M with M^-1 = L L^T:
///   log det(I + J_i M^-1 J_i^T) = log det(I + A A^T), A = J_i L,
/// into out[k]. L: cols x cols, row-major, lower triangular (entries above the diagonal are not
/// read). Single precision products (the gains rank candidates; their order needs no more digits),
/// the small factorisation in double. Runs on the core's thread pool; InputError for an index out
/// of [0, n) or a block that is not positive definite (NaN in J or L).
void d_optimal_gains(const float* J, std::size_t n, int rows, int cols, const std::int64_t* idx, std::size_t m,
                     const float* L, float* out);

}  // namespace kincal
