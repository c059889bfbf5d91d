// Stage 3: the Delassus operator W = G Ŵ Gᵀ (and Y = Ŵ Gᵀ, which maps impulses
// to velocity changes). Every row of G touches at most two bodies, i.e. 12 of
// its 6N columns, so both products are formed from those 6-column pieces only:
// O(r·12·6N) and O(r²·12) instead of O(r·(6N)²) and O(r²·6N) for dense products.
// W is filled symmetrically. Ŵ itself is block-diagonal over the bodies, or over
// the groups of bodies springs and PD actuators join (ModelFacts::coupled), so
// W_ij needs only the pieces of row i on bodies where column j of Y is nonzero
// (none, for rows on bodies Ŵ does not couple).
#include <array>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "step_stages.hpp"

namespace nscd {
namespace {

// The dot product of two 6-vectors, summed as Eigen sums a non-vectorised
// fixed-size 6 (G's row pieces are strided): (0 + (1 + 2)) + (3 + (4 + 5)).
inline double dot6(const double* a, const double* b) {
  return (a[0] * b[0] + (a[1] * b[1] + a[2] * b[2])) + (a[3] * b[3] + (a[4] * b[4] + a[5] * b[5]));
}

// One row's piece of Y on a body, y = B g (B: the body's block of M^-1, g: the
// row's piece of G, stride ld), as Eigen's 6 x 6 product forms it: each entry
// summed over the block's columns in order from the first product, then added to
// the zeroed column (+0.0). Less its exact +-0 terms (B's zeros), which change no
// partial sum that is not zero, and a zero sum comes out +0 both ways.
inline void applyBodyInverse(const StepWorkspace::BodyMassInverse& bi, const double* g, Eigen::Index ld,
                             double* y) {
  const double g3 = g[3 * ld], g4 = g[4 * ld], g5 = g[5 * ld];
  for (int k = 0; k < 3; ++k) y[k] = bi.lin[k] * g[k * ld] + 0.0;
  for (int k = 0; k < 3; ++k) y[3 + k] = ((bi.ang[k][0] * g3 + bi.ang[k][1] * g4) + bi.ang[k][2] * g5) + 0.0;
}

// W's rows i0 .. i0 + S - 1 of one block (and the columns they mirror into),
// against every row up to the block's end: W_ij = sum over the block's bodies
// where column j of Y is nonzero of dot6(G_i piece, Y_j piece), each sum from +0
// in the bodies' order. A piece against a body where column j of Y is zero adds
// +-0 to a sum that starts at +0: skipping it leaves W bit for bit the same.
template <int S>
void assembleBlockRows(StepWorkspace& ws, int i0, bool masks, const double* Y, Eigen::Index ldy) {
  // The block's pieces of G (one per body it touches), copied out of G's strided rows.
  int off[2] = {0, 0};
  std::uint64_t bit[2] = {0, 0};
  double g[S][2][6];
  int np = 0;
  for (int body : ws.row_bodies[i0]) {
    if (body == kGround) continue;
    off[np] = 6 * body;
    bit[np] = masks ? std::uint64_t{1} << body : ~std::uint64_t{0};
    for (int a = 0; a < S; ++a)
      for (int k = 0; k < 6; ++k) g[a][np][k] = ws.G(i0 + a, 6 * body + k);
    ++np;
  }
  const std::uint64_t touched = bit[0] | bit[1];
  double* W = ws.W.data();
  const Eigen::Index ldw = ws.W.outerStride();
  for (int j = 0; j < i0 + S; ++j) {
    const std::uint64_t support = ws.row_support[j];
    const int first = j > i0 ? j - i0 : 0;  // W_ij for i >= j only
    double* wc = W + j * ldw + i0;          // column j at row i0
    double* wr = W + i0 * ldw + j;          // row j at column i0 (stride ldw)
    double w[S];
    for (int a = 0; a < S; ++a) w[a] = 0;
    if (support & touched) {
      const double* yj = Y + j * ldy;
      for (int q = 0; q < np; ++q) {
        if (!(support & bit[q])) continue;
        const double* y = yj + off[q];
        for (int a = first; a < S; ++a) w[a] += dot6(g[a][q], y);
      }
    }
    for (int a = first; a < S; ++a) {
      wc[a] = w[a];
      wr[a * ldw] = w[a];
    }
  }
}

// W's rows of block bi against those of an earlier (or the same) block bj, in W's
// lower triangle (W_ij, i >= j, at W[j * ldw + i]): over the bodies both blocks
// touch, dot6(G_i piece, Y_j piece) added to an entry zeroed before (+0), as
// assembleBlockRows sums it (with at most two terms the bodies' order does not
// change the sum: +0 + x + y is y + x's value for every x, y, signed zeros too).
// gi: block bi's pieces, copied out of G; qi: their bodies.
template <int S>
void addBlockPair(const double (&gi)[6][2][6], const int (&qi)[2], int npi, const ConstraintBlock& bi,
                  const ConstraintBlock& bj, const double* Y, Eigen::Index ldy, double* W, Eigen::Index ldw) {
  const int ja = bj.body_a, jb = bj.body_b == bj.body_a ? kGround : bj.body_b;
  const bool same = &bi == &bj;
  for (int q = 0; q < npi; ++q) {
    const int body = qi[q];
    if (body != ja && body != jb) continue;
    for (int c = 0; c < bj.size; ++c) {
      const int j = bj.row + c;
      const double* y = Y + j * ldy + 6 * body;
      double* wc = W + j * ldw + bi.row;  // column j at block bi's first row
      for (int a = same ? c : 0; a < S; ++a) wc[a] += dot6(gi[a][q], y);
    }
  }
}

// f(std::integral_constant<int, C>) for each C in turn.
template <typename F, int... C>
inline void forEachIndex(F&& f, std::integer_sequence<int, C...>) {
  (f(std::integral_constant<int, C>{}), ...);
}

// A known block's rows (ang: their angular entries of G on one body, lin: their
// linear entry at their axis, row_of_axis: the row along each axis, or -1)
// against column j of Y on that body (y: its piece): the S sums of W_ij, the
// angular dot product plus, for a row along the column row's axis k, its one
// linear product (assembleKnownLowerBlockRows). Rows from `From` on only (the
// block against itself: its lower triangle).
template <int S, int From = 0>
inline void knownPieceSums(const double (&ang)[3][S], const double (&lin)[S], const int (&row_of_axis)[3], int k,
                           const double* y, double (&w)[S]) {
  const double y3 = y[3], y4 = y[4], y5 = y[5];
  for (int a = From; a < S; ++a) w[a] = ang[0][a] * y3 + (ang[1][a] * y4 + ang[2][a] * y5);
  if (k != kLinearZero && row_of_axis[k] >= From) {
    const int a = row_of_axis[k];
    w[a] = lin[a] * y[k] + w[a];
  }
}

// Those sums against every row of another block on the body, written into W's
// columns (wc: W at block bi's first row of column other.row): as +0 plus them
// (kFirst: w + 0.0, the same value) or added.
template <int S, bool kFirst>
void addKnownPieces(const double (&ang)[3][S], const double (&lin)[S], const int (&row_of_axis)[3],
                    const ConstraintBlock& other, const double* y, Eigen::Index ldy, double* wc, Eigen::Index ldw) {
  for (int c = 0; c < other.size; ++c, y += ldy, wc += ldw) {
    double w[S];
    knownPieceSums<S>(ang, lin, row_of_axis, other.linear_axis[c], y, w);
    for (int a = 0; a < S; ++a) wc[a] = kFirst ? w[a] + 0.0 : wc[a] + w[a];
  }
}

// assembleLowerBlockRows where every block's rows have known linear parts
// (ConstraintBlock::linear_known): dot6 less the products of the exact zeros. A
// row of Y has the linear pattern of its row of G (Y's linear part is the body's
// 1/m times G's, plus +0), so of the linear part's three products all are +-0 but
// for G_i and G_j along the same axis k, where the one left, G_ik Y_jk, is the
// linear sum's value; else that sum is +-0, which leaves the angular sum's value
// (a zero's sign aside: every W entry is summed from +0, which absorbs it).
// Nothing skipped can be a NaN: the known linear entries are finite, and so are
// Y's (1/m times them). Block bi's pieces of G are copied out as columns over its
// rows (the angular sums of its S rows against one column of Y side by side).
// W's entries are not zeroed before: the first body's sums are written as +0 plus
// them, a block pair's entries without a shared body as +0.
template <int S>
void assembleKnownLowerBlockRows(const StepWorkspace& ws, int bi, const double* Y, Eigen::Index ldy, double* W,
                                 Eigen::Index ldw) {
  const ConstraintBlock& blk = ws.blocks[bi];
  double ang[2][3][S];  // per body: G's angular entries, row by row
  double lin[2][S];     // per body: a row's linear entry at its axis
  int row_of_axis[3] = {-1, -1, -1};  // the block's row along each axis (one at most)
  for (int a = 0; a < S; ++a)
    if (blk.linear_axis[a] != kLinearZero) row_of_axis[blk.linear_axis[a]] = a;
  int qi[2] = {kGround, kGround};
  int np = 0;
  const Eigen::Index ldg = ws.G.outerStride();
  for (int body : {blk.body_a, blk.body_b == blk.body_a ? kGround : blk.body_b}) {
    if (body == kGround) continue;
    const double* gc = ws.G.data() + blk.row + 6 * body * ldg;
    for (int a = 0; a < S; ++a) {
      for (int k = 0; k < 3; ++k) ang[np][k][a] = gc[a + (3 + k) * ldg];
      const int axis = blk.linear_axis[a];
      lin[np][a] = axis == kLinearZero ? 0.0 : gc[a + axis * ldg];
    }
    qi[np++] = body;
  }
  for (int bj = 0; bj < bi; ++bj) {
    const ConstraintBlock& other = ws.blocks[bj];
    const int ja = other.body_a, jb = other.body_b == other.body_a ? kGround : other.body_b;
    double* wc = W + other.row * ldw + blk.row;
    bool first = true;
    for (int q = 0; q < np; ++q) {
      const int body = qi[q];
      if (body != ja && body != jb) continue;
      const double* y = Y + other.row * ldy + 6 * body;
      if (first)
        addKnownPieces<S, true>(ang[q], lin[q], row_of_axis, other, y, ldy, wc, ldw);
      else
        addKnownPieces<S, false>(ang[q], lin[q], row_of_axis, other, y, ldy, wc, ldw);
      first = false;
    }
    if (first)  // no body shared
      for (int c = 0; c < other.size; ++c)
        for (int a = 0; a < S; ++a) wc[c * ldw + a] = 0;
  }
  // The block against itself: its lower triangle, a column at a time (C: its
  // index, a template argument so that each column's loops unroll).
  for (int q = 0; q < np; ++q) {
    const auto column = [&](auto c_constant) {
      constexpr int c = decltype(c_constant)::value;
      double w[S];
      knownPieceSums<S, c>(ang[q], lin[q], row_of_axis, blk.linear_axis[c], Y + (blk.row + c) * ldy + 6 * qi[q], w);
      double* wc = W + (blk.row + c) * ldw + blk.row;
      for (int a = c; a < S; ++a) wc[a] = q == 0 ? w[a] + 0.0 : wc[a] + w[a];
    };
    forEachIndex(column, std::make_integer_sequence<int, S>{});
  }
  if (np == 0)
    for (int c = 0; c < S; ++c)
      for (int a = c; a < S; ++a) W[(blk.row + c) * ldw + blk.row + a] = 0;
}

template <int S>
void assembleLowerBlockRows(const StepWorkspace& ws, int bi, const double* Y, Eigen::Index ldy, double* W,
                            Eigen::Index ldw) {
  const ConstraintBlock& blk = ws.blocks[bi];
  double g[6][2][6];
  int qi[2] = {kGround, kGround};
  int np = 0;
  const Eigen::Index ldg = ws.G.outerStride();
  for (int body : {blk.body_a, blk.body_b == blk.body_a ? kGround : blk.body_b}) {
    if (body == kGround) continue;
    const double* gc = ws.G.data() + blk.row + 6 * body * ldg;
    for (int a = 0; a < S; ++a)
      for (int k = 0; k < 6; ++k) g[a][np][k] = gc[a + k * ldg];
    qi[np++] = body;
  }
  for (int bj = 0; bj <= bi; ++bj) addBlockPair<S>(g, qi, np, blk, ws.blocks[bj], Y, ldy, W, ldw);
}

}  // namespace

void assembleEqualityDelassus(StepWorkspace& ws, int r) {
  // Each row's bodies and the bodies of its column of Y (its own: Ŵ = M^-1 is
  // block-diagonal), as assembleDelassus sets them for applyImpulses.
  for (const ConstraintBlock& blk : ws.blocks) {
    const int b = blk.body_b == blk.body_a ? kGround : blk.body_b;
    std::uint64_t support = 0;
    for (int body : {blk.body_a, b})
      if (body != kGround) support |= std::uint64_t{1} << body;
    for (int k = 0; k < blk.size; ++k) {
      ws.row_bodies[blk.row + k] = {blk.body_a, b};
      ws.row_support[blk.row + k] = support;
    }
  }
  const Eigen::Index ldg = ws.G.outerStride();
  // Y's columns, a block at a time: its bodies' pieces written whole
  // (applyBodyInverse; a known row's linear entries off its axis are +0: 1/m
  // times G's +0, plus +0), the other bodies' zeroed.
  const int nb = ws.nbodies;
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.row >= r) continue;
    const std::array<int, 2>& bodies = ws.row_bodies[blk.row];
    for (int c = 0; c < nb; ++c) {
      if (c == bodies[0] || c == bodies[1]) continue;
      for (int i = blk.row; i < blk.row + blk.size; ++i)
        for (int k = 0; k < 6; ++k) ws.Y(6 * c + k, i) = 0;
    }
    for (int body : bodies) {
      if (body == kGround) continue;
      const StepWorkspace::BodyMassInverse& bm = ws.body_mass_inverse[body];
      for (int i = blk.row; i < blk.row + blk.size; ++i) {
        const double* g = ws.G.data() + i + 6 * body * ldg;
        double* y = ws.Y.col(i).data() + 6 * body;
        const int axis = blk.linear_axis[i - blk.row];
        if (!blk.linear_known) {
          applyBodyInverse(bm, g, ldg, y);
          continue;
        }
        const double g3 = g[3 * ldg], g4 = g[4 * ldg], g5 = g[5 * ldg];
        for (int k = 0; k < 3; ++k) y[k] = 0.0;
        if (axis != kLinearZero) y[axis] = bm.lin[axis] * g[axis * ldg] + 0.0;
        if (bm.ang_diagonal) {
          // The sums less their +-0 products (finite G): a nonzero diagonal product
          // is the sum; a zero one leaves a +-0 sum that the + 0.0 makes +0 both
          // ways. (A non-finite G makes W's diagonal non-finite both ways, and
          // factorRows hands the step to the general path, which forms Y again.)
          y[3] = bm.ang[0][0] * g3 + 0.0;
          y[4] = bm.ang[1][1] * g4 + 0.0;
          y[5] = bm.ang[2][2] * g5 + 0.0;
          continue;
        }
        for (int k = 0; k < 3; ++k) y[3 + k] = ((bm.ang[k][0] * g3 + bm.ang[k][1] * g4) + bm.ang[k][2] * g5) + 0.0;
      }
    }
  }
  double* W = ws.W.data();
  const Eigen::Index ldw = ws.W.outerStride();
  const double* Y = ws.Y.data();
  const Eigen::Index ldy = ws.Y.outerStride();
  bool known = true;  // every block's linear parts known: their zeros skipped
  for (const ConstraintBlock& blk : ws.blocks) known = known && blk.linear_known;
  if (!known)  // assembleLowerBlockRows adds to W
    for (int j = 0; j < r; ++j)
      for (int i = j; i < r; ++i) W[j * ldw + i] = 0;
  for (int bi = 0; bi < int(ws.blocks.size()); ++bi) {
    if (ws.blocks[bi].row >= r) continue;
    // Two switches, not one dispatch taking `known`: that one cost the four-bar
    // 43 instructions a step (callgrind, nscd_mujoco_compare --single fourbar).
    // Switches, not withRowCount (row_count_dispatch.hpp): its chain of
    // comparisons over 1-6 rows cost 10, 19 and 55 instructions a step more
    // (pendulum, double pendulum, four-bar).
    if (known) {
      switch (ws.blocks[bi].size) {
        case 1: assembleKnownLowerBlockRows<1>(ws, bi, Y, ldy, W, ldw); break;
        case 2: assembleKnownLowerBlockRows<2>(ws, bi, Y, ldy, W, ldw); break;
        case 3: assembleKnownLowerBlockRows<3>(ws, bi, Y, ldy, W, ldw); break;
        case 4: assembleKnownLowerBlockRows<4>(ws, bi, Y, ldy, W, ldw); break;
        case 5: assembleKnownLowerBlockRows<5>(ws, bi, Y, ldy, W, ldw); break;
        case 6: assembleKnownLowerBlockRows<6>(ws, bi, Y, ldy, W, ldw); break;
        default: break;
      }
      continue;
    }
    switch (ws.blocks[bi].size) {
      case 1: assembleLowerBlockRows<1>(ws, bi, Y, ldy, W, ldw); break;
      case 2: assembleLowerBlockRows<2>(ws, bi, Y, ldy, W, ldw); break;
      case 3: assembleLowerBlockRows<3>(ws, bi, Y, ldy, W, ldw); break;
      case 4: assembleLowerBlockRows<4>(ws, bi, Y, ldy, W, ldw); break;
      case 5: assembleLowerBlockRows<5>(ws, bi, Y, ldy, W, ldw); break;
      case 6: assembleLowerBlockRows<6>(ws, bi, Y, ldy, W, ldw); break;
      default: break;  // no block has more than 6 rows (ConstraintBlock::error)
    }
  }
}

void assembleDelassus(const Eigen::MatrixXd& iteration_inverse, bool block_diagonal,
                      StepWorkspace& ws, int from, int r) {
  // Bodies of each row (kGround = none), and the bodies where its column of Y
  // can be nonzero (its bodies' coupled groups; all of them past 64 bodies).
  const bool masks = ws.nbodies <= 64;
  for (const ConstraintBlock& blk : ws.blocks) {
    const int b = blk.body_b == blk.body_a ? kGround : blk.body_b;
    std::uint64_t support = masks ? 0 : ~std::uint64_t{0};
    for (int body : {blk.body_a, b})
      if (masks && body != kGround)
        support |= block_diagonal ? std::uint64_t{1} << body : ws.facts.coupled_mask[body];
    for (int k = 0; k < blk.size; ++k) {
      ws.row_bodies[blk.row + k] = {blk.body_a, b};
      ws.row_support[blk.row + k] = support;
    }
  }
  const int n = ws.n;
  // Ŵ = M^-1 (the projection's, or the step's without stiff elements, a copy), in
  // the form bodies have: per body, its piece.
  const bool is_mass_inverse = &iteration_inverse == &ws.mass_inverse || !ws.facts.stiff;
  const bool by_body = block_diagonal && ws.mass_inverse_by_body && is_mass_inverse;
  const Eigen::Index ldg = ws.G.outerStride();
  for (int i = from; i < r; ++i) {
    auto y = ws.Y.col(i).head(n);
    y.setZero();
    if (by_body) {
      for (int body : ws.row_bodies[i])
        if (body != kGround)
          applyBodyInverse(ws.body_mass_inverse[body], ws.G.data() + i + 6 * body * ldg, ldg,
                           y.data() + 6 * body);
      continue;
    }
    for (int body : ws.row_bodies[i]) {
      if (body == kGround) continue;
      const Vec6 g = ws.G.row(i).segment<6>(6 * body).transpose();
      if (block_diagonal) {  // no coupling between bodies: only this body's 6 x 6 block
        y.segment<6>(6 * body).noalias() += iteration_inverse.block<6, 6>(6 * body, 6 * body) * g;
        continue;
      }
      // Ŵ couples a body only with those of its stiff group (iteration_matrix.cpp).
      for (int c : ws.facts.coupled[body])
        y.segment<6>(6 * c).noalias() += iteration_inverse.block<6, 6>(6 * c, 6 * body) * g;
    }
  }
  const double* Y = ws.Y.data();
  const Eigen::Index ldy = ws.Y.outerStride();
  // Block by block, its size a template argument (the loops unroll): a block's
  // rows share their bodies, so each piece of Y's column j is loaded and tested
  // once for all of them.
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.row < from || blk.row >= r) continue;
    switch (blk.size) {
      case 1: assembleBlockRows<1>(ws, blk.row, masks, Y, ldy); break;
      case 2: assembleBlockRows<2>(ws, blk.row, masks, Y, ldy); break;
      case 3: assembleBlockRows<3>(ws, blk.row, masks, Y, ldy); break;
      case 4: assembleBlockRows<4>(ws, blk.row, masks, Y, ldy); break;
      case 5: assembleBlockRows<5>(ws, blk.row, masks, Y, ldy); break;
      case 6: assembleBlockRows<6>(ws, blk.row, masks, Y, ldy); break;
      default: break;  // no block has more than 6 rows (ConstraintBlock::error)
    }
  }
}

}  // namespace nscd
