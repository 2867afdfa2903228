// resampled_states (filter/ensemble.h) on a worker pool, by blocks of rows: each row of the
// new states depends on that row of the predicted states alone (its mean, its row of L), so
// the blocks are independent; and each block's products sum over the S sigma points (or the p
// directions) in the same order as the whole matrix's, so the result is the same bits on any
// number of threads (tested in tests/ensemble/threaded_resampling_test.cpp). The CPU back end
// and rank 0 of an MPI run (host/mpi/) both re-sample this way, which keeps their results
// alike; at S = 129 on the 38k liver the serial re-sampling was the part of rank 0's step that
// outgrew a machine's share on 64 machines (bench/mpi_scaling_model.py).
#pragma once

#include <Eigen/Core>

#include "filter/ensemble.h"
#include "host/common/worker_pool.h"

namespace sigmafem {

// Rows per block: fixed, so that the blocks, and the bits, do not depend on the thread count.
constexpr Eigen::Index kResamplingBlockRows = 1024;

Eigen::MatrixXd resampled_states_on(WorkerPool& pool, const Eigen::MatrixXd& Y, const Recentering& recentering);

}  // namespace sigmafem
