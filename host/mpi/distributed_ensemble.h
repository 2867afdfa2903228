// DistributedEnsemble: one ensemble's S sigma points spread over the MPI ranks (issue 19,
// `mpirun -n R sigmafem estimate ...`). Every rank runs its share (host/mpi/sigma_share.h) on
// its own back end; rank 0 runs the filter with this object as its Ensemble, and the other
// ranks serve their shares on its commands (serve_ensemble) until it stops them. What crosses
// between ranks per filter step (ARCHITECTURE.md, "Over MPI ranks", says why these):
//   set_parameters   MPI_Bcast of theta (p x S) from rank 0; each rank takes its columns
//   advance          MPI_Bcast of the SO's position; MPI_Gatherv of each sigma point's solver report
//   observations     MPI_Gatherv of each rank's 3m x S_r predicted observations
//   recenter         MPI_Gatherv of each rank's states (positions and velocities, n x S_r each)
//                    to rank 0, which re-samples all S in double precision with the CPU back
//                    end's own code (resampled_states), then MPI_Scatterv of the new states
// Rank 0 re-samples the whole ensemble in sigma order, so the result does not depend on R:
// the same bits on 1, 2 or 3 ranks, and on the CPU back end the same bits as without MPI.
// A rank that fails reports it in its next reply; rank 0 finishes the command's collectives,
// throws the failure (naming the rank), and its caller stops every rank with it (stop()), so
// each rank ends with a message and the same exit code, and none waits forever.
#pragma once

#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "host/common/worker_pool.h"
#include "host/ensemble/simulation_ensemble.h"
#include "host/mpi/ranks.h"
#include "host/mpi/sigma_share.h"

namespace sigmafem {

class DistributedEnsemble : public Ensemble {
 public:
  // `local`: rank 0's share of the S sigma points (sigma_share(S, R, 0)). Call after
  // agree_on_shares.
  DistributedEnsemble(std::unique_ptr<SimulationEnsemble> local, int sigma_count);
  ~DistributedEnsemble() override;   // stops the other ranks if stop() was not called
  DistributedEnsemble(const DistributedEnsemble&) = delete;
  DistributedEnsemble& operator=(const DistributedEnsemble&) = delete;

  int sigma_count() const override { return S_; }
  int parameter_count() const override { return local_->parameter_count(); }
  int observation_count() const override { return local_->observation_count(); }
  void set_parameters(const Eigen::MatrixXd& theta) override;
  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override;

  // Ends the other ranks' service: at the end of a run with no `failure`; else they end with
  // an error carrying `failure` and `exit_code` (the code main gives for it).
  void stop(int exit_code = 0, const std::string& failure = "");
  // The same after `failure` ended rank 0's run: the exit code and message main gives for it.
  void stop_after(const std::exception_ptr& failure);
  // Seconds rank 0 spent in the re-centrings so far: reading its share, the gather, the
  // re-sampling of all S and the scatter (what the benchmark's model of many machines needs).
  double recenter_seconds() const { return recenter_seconds_; }

 private:
  std::unique_ptr<SimulationEnsemble> local_;
  int S_;
  Eigen::Index state_size_ = 0;      // n: 3 per node
  std::vector<SigmaShare> shares_;   // per rank
  bool serving_ = true;              // the other ranks wait for commands
  int advances_ = 0;
  double recenter_seconds_ = 0.0;
  // Rank 0's threads for re-sampling all S (its share of the machine's cores; its share of the
  // ensemble is idle meanwhile).
  std::unique_ptr<WorkerPool> pool_;
};

// On every rank other than 0: runs this rank's share `local` on rank 0's commands until rank 0
// stops the run. Returns when the run completed; throws (as main reports it) when rank 0 ended
// it with an error, this rank's own if it was the one that failed.
void serve_ensemble(SimulationEnsemble& local, int sigma_count);

// Every rank, after making its share of the ensemble (`failure` set if that threw; then
// `local` is null): whether every rank has one, and whether they all run the same ensemble
// (sigma points, parameters, observations, state size). Throws on every rank when not: the
// failing rank its own error, the others the same kind of error naming that rank.
void agree_on_shares(const std::exception_ptr& failure, const SimulationEnsemble* local, int sigma_count);

// Every rank: this rank's share of S sigma points, made by `make(count)` (make_ensemble with
// the share's count), once every rank has agreed (agree_on_shares).
template <class Make>
std::unique_ptr<SimulationEnsemble> make_share(int sigma_count, Make make) {
  std::unique_ptr<SimulationEnsemble> local;
  std::exception_ptr failure;
  try {
    local = make(sigma_share(sigma_count, ranks().size, ranks().rank).count);
  } catch (...) {
    failure = std::current_exception();
  }
  agree_on_shares(failure, local.get(), sigma_count);
  return local;
}

}  // namespace sigmafem
