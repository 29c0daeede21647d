#pragma once
// Ceres options of the fusion's batch solves after the drive (the smoother, the global pose
// graph): single-threaded so a run is the same bit for bit whatever the machine, silent, and
// sparse normal Cholesky where Ceres has a sparse backend (the graphs are chains with a few long
// edges: sparse keeps hours of drive cheap), dense QR otherwise.
#include <ceres/solver.h>

namespace gvio::fusion {

inline ceres::Solver::Options batchSolverOptions(int max_iterations) {
  ceres::Solver::Options options;
  const bool sparse = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE);
  options.linear_solver_type = sparse ? ceres::SPARSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  return options;
}

}  // namespace gvio::fusion
