// Kernels whose loops run faster with their bounds known at compile time:
// withRowCount(RowCounts<N...>{}, n, f) calls f(std::integral_constant<int, N>{})
// for the N equal to n, else f(std::integral_constant<int, 0>{}) (0: the bound is
// n, not known). Each kernel is the same arithmetic for every N; only its loops'
// bounds are constants.
#pragma once

#include <type_traits>
#include <utility>

namespace nscd {

template <int... N>
struct RowCounts {};

// The joints' common problem sizes: 5 rows a revolute or prismatic joint, 6 a
// fixed one, and the sums of two to four of them in small mechanisms (a double
// pendulum 10, a four-bar 20). The factor (pivotedLdlt) dispatches by a switch
// of its own over the small ones alone: at 20 its instance cost the four-bar 133
// instructions a step more (callgrind, nscd_mujoco_compare --single fourbar).
using JointRowCounts = RowCounts<5, 6, 10, 11, 12, 15, 20>;

template <int... N, typename F>
inline auto withRowCount(RowCounts<N...>, int n, F&& f) -> decltype(f(std::integral_constant<int, 0>{})) {
  using Result = decltype(f(std::integral_constant<int, 0>{}));
  if constexpr (std::is_void_v<Result>) {
    const bool known = ((n == N ? (f(std::integral_constant<int, N>{}), true) : false) || ...);
    if (!known) f(std::integral_constant<int, 0>{});
  } else {
    Result result{};
    const bool known = ((n == N ? (result = f(std::integral_constant<int, N>{}), true) : false) || ...);
    if (!known) result = f(std::integral_constant<int, 0>{});
    return result;
  }
}

}  // namespace nscd
