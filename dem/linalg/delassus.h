#pragma once
/// @file The Delassus operator W = H M~^-1 H^T of a step's contacts as a sparse matrix.
///
/// Contact i's local velocity is u_i = sum_j W_ij r_j + u_free,i, with 2x2 blocks
///     W_ij = sum over the bodies b that i and j share of s_ib s_jb H_ib^T M_b^-1 H_jb
///          + B_i^T G_AB B_j                      (both against one boundary body),
/// where H_ib^T = [n^T, arm_n; t^T, arm_t] maps body b's velocity (v_x, v_y, spin) to the
/// local frame of i, s_ib = -1 for side 0 and +1 for side 1, M_b^-1 the inverse masses
/// (0 for imposed dofs), and for half-disc contacts B_i the 4x2 map from (r_n, r_t) to the
/// impulses -J_A^T f, -J_B^T f on the edge's two nodes, G_AB that body's compliance
/// between those nodes (dem/engine/boundary.h; zero between two bodies' nodes). Units: m/s per N s/m. Periodic
/// contacts need nothing special: their arms already use the periodic image.
/// W_ii is the contact's own block (BodyState::delassus_block).
///
/// A rigid body touched by m contacts (a wall clump) couples them all: an m x m dense
/// block of W, m^3 / 3 flops in a Cholesky factorisation (about 840 contacts on each wall
/// of a 16 000-grain cell). It is also the rank-k product U_b U_b^T, U_b's rows
/// s_ib H_ib^T M_b^(-1/2) over the k dofs of b that are not imposed (k <= 3): with a
/// LowRankBodies, bodies with more than its contact limit are left out of the sparse
/// matrix and returned as those columns, W = W_sparse + U U^T.

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace tribo::dem
{
  struct Contact;
  struct BodyState;

  /// Which components of the local problems the matrix holds.
  enum class DelassusPart
  {
    normal, ///< n x n: the (n, n) entry of every block (frictionless problems)
    full    ///< 2n x 2n: rows and columns 2i (normal) and 2i + 1 (tangent) of contact i
  };

  /// The rigid bodies kept out of the sparse matrix: those with more than contact_limit
  /// contacts. U has one column per free dof of each (m/s per N s/m, square-rooted).
  struct LowRankBodies
  {
    unsigned int    contact_limit = 64;
    Eigen::MatrixXd U;
  };

  /// W for @p contacts against @p state's inverse masses and boundary compliance, in
  /// compressed-column storage, both triangles, rows and columns in the contacts' order
  /// (the detection's: neighbours in space are neighbours in the matrix). With
  /// @p low_rank, the returned matrix is W - U U^T, U in low_rank->U. Every contact's own
  /// block is stored (explicit zeros where no body couples). Built column by column, in
  /// chunks of columns on @p threads threads: the same bits on any number of threads.
  Eigen::SparseMatrix<double> assemble_delassus(const std::vector<Contact> &contacts,
                                                const BodyState &state, DelassusPart part,
                                                LowRankBodies *low_rank = nullptr, unsigned int threads = 1);
} // namespace tribo::dem
