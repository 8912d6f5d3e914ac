#pragma once
// The sparse matrix type of the Jacobians and the linear solvers: compressed columns, int indices.
#include <Eigen/SparseCore>

#include <jelly/core/types.hpp>

namespace jelly {

using SparseMatrix = Eigen::SparseMatrix<Real, Eigen::ColMajor, int>;

}  // namespace jelly
