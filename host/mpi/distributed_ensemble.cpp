#include "host/mpi/distributed_ensemble.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "host/common/device_error.h"
#include "host/common/input_error.h"
#include "host/common/interruption.h"
#include "host/ensemble/threaded_resampling.h"
#include "host/mpi/ranks.h"
#if SIGMAFEM_HAVE_MPI
#  include <mpi.h>
#endif

namespace sigmafem {

#if SIGMAFEM_HAVE_MPI
namespace {

enum Command : int { kSetParameters = 1, kAdvance, kObservations, kRecenter, kStop };
constexpr int kMessageTag = 19;

// The exit code main gives for an error (host/cli/main.cpp), and its message.
int exit_code_of(const std::exception_ptr& failure, std::string& message) {
  try {
    std::rethrow_exception(failure);
  } catch (const Interrupted& e) {
    message = e.what();
    return 128 + e.signal_number();
  } catch (const InputError& e) {
    message = e.what();
    return 2;
  } catch (const DeviceError& e) {
    message = e.what();
    return 3;
  } catch (const std::exception& e) {
    message = e.what();
    return 1;
  } catch (...) {
    message = "an unknown error";
    return 1;
  }
}

// The error main reports with exit code `code`.
[[noreturn]] void throw_as(int code, const std::string& message) {
  if (code >= 128) throw Interrupted(code - 128);
  if (code == 2) throw InputError(message);
  if (code == 3) throw DeviceError(message);
  throw std::runtime_error(message);
}

void broadcast_command(int command, int argument = 0) {
  int header[2] = {command, argument};
  MPI_Bcast(header, 2, MPI_INT, 0, MPI_COMM_WORLD);
}

void broadcast_text(std::string& text, int root) {
  int size = static_cast<int>(text.size());
  MPI_Bcast(&size, 1, MPI_INT, root, MPI_COMM_WORLD);
  text.resize(static_cast<std::size_t>(size));
  MPI_Bcast(text.data(), size, MPI_CHAR, root, MPI_COMM_WORLD);
}

int checked_count(long count) {
  if (count > 2147483647L)
    throw std::runtime_error("distributed ensemble: one rank's share is over 2^31 numbers; use more ranks");
  return static_cast<int>(count);
}

// Rank 0's counts and offsets for MPI_Gatherv and MPI_Scatterv: each rank's `leading` numbers
// (a reply's status code first, then a header), then `per_sigma` numbers for each of its sigma
// points.
struct ReplyLayout {
  std::vector<int> counts, offsets;
  int total = 0;
  ReplyLayout(const std::vector<SigmaShare>& shares, int leading, long per_sigma) {
    for (const SigmaShare& share : shares) {
      offsets.push_back(total);
      counts.push_back(checked_count(leading + per_sigma * share.count));
      total = checked_count(static_cast<long>(total) + counts.back());
    }
  }
};

// A failure message from rank `rank`, whatever its length.
std::string receive_message(int rank) {
  MPI_Status status;
  MPI_Probe(rank, kMessageTag, MPI_COMM_WORLD, &status);
  int length = 0;
  MPI_Get_count(&status, MPI_CHAR, &length);
  std::string message(static_cast<std::size_t>(length), '\0');
  MPI_Recv(message.data(), length, MPI_CHAR, rank, kMessageTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return message;
}

// The tests of a failing rank (tests/mpi/): SIGMAFEM_FAIL_RANK=R:N makes rank R fail in its
// N-th advance (R:N:abort ends the process there, as a crash would). Nothing without it.
void fail_if_asked(int advances) {
  static const std::string spec = std::getenv("SIGMAFEM_FAIL_RANK") ? std::getenv("SIGMAFEM_FAIL_RANK") : "";
  if (spec.empty()) return;
  int rank = -1, step = -1;
  char how[16] = "";
  if (std::sscanf(spec.c_str(), "%d:%d:%15s", &rank, &step, how) < 2 || rank != ranks().rank || step != advances)
    return;
  if (std::string(how) == "abort") std::abort();
  throw std::runtime_error("failed in advance " + std::to_string(advances) + " as SIGMAFEM_FAIL_RANK asks");
}

// A rank's failure as rank 0 learns it: none when code is 0.
struct RankFailure {
  int rank = -1, code = 0;
  std::string message;
  [[noreturn]] void raise() const { throw_as(code, "rank " + std::to_string(rank) + ": " + message); }
};

// Rank 0's side of a reply: gathers every rank's numbers (rank 0's own `mine`) and the
// messages of those that failed; returns the first failure (code 0: none). Never throws
// between collectives, so that no rank is left waiting in one.
RankFailure gather_replies(std::vector<double>& mine, const ReplyLayout& layout, std::vector<double>& all) {
  all.assign(static_cast<std::size_t>(layout.total), 0.0);
  MPI_Gatherv(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(), layout.counts.data(),
              layout.offsets.data(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  RankFailure first;
  for (std::size_t r = 1; r < layout.counts.size(); ++r) {
    const int code = static_cast<int>(all[static_cast<std::size_t>(layout.offsets[r])]);
    if (code == 0) continue;
    std::string message = receive_message(static_cast<int>(r));
    if (first.code == 0) first = {static_cast<int>(r), code, std::move(message)};
  }
  return first;
}

// A worker rank: its share, and its first failure (reported in every reply after it; the
// rank skips the work of later commands and waits for rank 0 to stop the run).
struct Worker {
  SimulationEnsemble& local;
  SigmaShare share;
  std::exception_ptr failure;
  int code = 0;
  std::string message;

  template <class Work>
  void attempt(Work work) {
    if (failure) return;
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
      code = exit_code_of(failure, message);
    }
  }
  // This rank's reply to rank 0: `numbers` (status first), then its message if it failed.
  void reply(std::vector<double>& numbers) const {
    numbers[0] = code;
    MPI_Gatherv(numbers.data(), static_cast<int>(numbers.size()), MPI_DOUBLE, nullptr, nullptr, nullptr,
                MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (code != 0)
      MPI_Send(message.data(), static_cast<int>(message.size()), MPI_CHAR, 0, kMessageTag, MPI_COMM_WORLD);
  }
};

// One rank's solver report in a reply: factorisations, then per sigma point its iterations,
// relative residual and convergence.
void pack_report(const StepReport& report, std::vector<double>& numbers) {
  numbers[1] = report.factorisations;
  for (std::size_t i = 0; i < report.cg_iterations.size(); ++i) {
    numbers[2 + 3 * i] = report.cg_iterations[i];
    numbers[3 + 3 * i] = report.relative_residual[i];
    numbers[4 + 3 * i] = report.converged[i];
  }
}

}  // namespace

DistributedEnsemble::DistributedEnsemble(std::unique_ptr<SimulationEnsemble> local, int sigma_count)
    : local_(std::move(local)), S_(sigma_count), pool_(std::make_unique<WorkerPool>(ranks().cores_per_rank())) {
  for (int r = 0; r < ranks().size; ++r) shares_.push_back(sigma_share(S_, ranks().size, r));
  Eigen::MatrixXd X, V;
  local_->read_states(X, V);
  state_size_ = X.rows();
}

DistributedEnsemble::~DistributedEnsemble() {
  if (std::uncaught_exceptions() > 0)
    stop(1, "rank 0 ended the run with an error (its message says which)");
  else
    stop();
}

void DistributedEnsemble::stop_after(const std::exception_ptr& failure) {
  std::string message;
  const int code = exit_code_of(failure, message);
  stop(code, message);
}

void DistributedEnsemble::stop(int exit_code, const std::string& failure) {
  if (!serving_) return;
  serving_ = false;
  broadcast_command(kStop, exit_code);
  if (exit_code != 0) {
    std::string text = failure;
    broadcast_text(text, 0);
  }
}

void DistributedEnsemble::set_parameters(const Eigen::MatrixXd& theta) {
  check_parameter_matrix(theta, parameter_count(), S_, "DistributedEnsemble");
  broadcast_command(kSetParameters);
  Eigen::MatrixXd copy = theta;
  MPI_Bcast(copy.data(), checked_count(copy.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  local_->set_parameters(theta.leftCols(shares_[0].count));
}

StepReport DistributedEnsemble::advance(const Eigen::Vector3d& so_position) {
  broadcast_command(kAdvance);
  Eigen::Vector3d so = so_position;
  MPI_Bcast(so.data(), 3, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  const ReplyLayout layout(shares_, 2, 3);   // status, factorisations
  std::vector<double> mine(static_cast<std::size_t>(layout.counts[0]), 0.0), all;
  std::exception_ptr own;
  try {
    fail_if_asked(++advances_);
    pack_report(local_->advance(so), mine);
  } catch (...) {
    own = std::current_exception();
  }
  const RankFailure failure = gather_replies(mine, layout, all);
  if (own) std::rethrow_exception(own);
  if (failure.code != 0) failure.raise();
  StepReport report;
  for (std::size_t r = 0; r < shares_.size(); ++r) {
    const double* at = all.data() + layout.offsets[r];
    report.factorisations += static_cast<int>(at[1]);
    for (int i = 0; i < shares_[r].count; ++i) {
      report.cg_iterations.push_back(static_cast<int>(at[2 + 3 * i]));
      report.relative_residual.push_back(at[3 + 3 * i]);
      report.converged.push_back(static_cast<unsigned>(at[4 + 3 * i]));
    }
  }
  return report;
}

void DistributedEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  broadcast_command(kObservations);
  const int rows = observation_count();
  const ReplyLayout layout(shares_, 1, rows);
  std::vector<double> mine(static_cast<std::size_t>(layout.counts[0]), 0.0), all;
  std::exception_ptr own;
  try {
    Eigen::MatrixXd local;
    local_->predicted_observations(local);
    std::copy(local.data(), local.data() + local.size(), mine.begin() + 1);
  } catch (...) {
    own = std::current_exception();
  }
  const RankFailure failure = gather_replies(mine, layout, all);
  if (own) std::rethrow_exception(own);
  if (failure.code != 0) failure.raise();
  y.resize(rows, S_);
  for (std::size_t r = 0; r < shares_.size(); ++r)
    y.middleCols(shares_[r].first, shares_[r].count) =
        Eigen::Map<const Eigen::MatrixXd>(all.data() + layout.offsets[r] + 1, rows, shares_[r].count);
}

void DistributedEnsemble::recenter(const Recentering& recentering) {
  const auto start = std::chrono::steady_clock::now();
  broadcast_command(kRecenter);
  Eigen::MatrixXd X, V;
  std::exception_ptr own;
  try {
    local_->read_states(X, V);
  } catch (...) {
    own = std::current_exception();
  }
  // Every rank's states, sigma point s in column s: the state size is rank 0's (agree_on_shares
  // checked that every rank has it).
  const Eigen::Index n = state_size_;
  const ReplyLayout layout(shares_, 1, 2 * static_cast<long>(n));
  std::vector<double> mine(static_cast<std::size_t>(layout.counts[0]), 0.0), all;
  if (!own) {
    std::copy(X.data(), X.data() + X.size(), mine.begin() + 1);
    std::copy(V.data(), V.data() + V.size(), mine.begin() + 1 + X.size());
  }
  const RankFailure failure = gather_replies(mine, layout, all);
  Eigen::MatrixXd all_X(n, S_), all_V(n, S_);
  for (std::size_t r = 0; r < shares_.size(); ++r) {
    const double* at = all.data() + layout.offsets[r] + 1;
    const Eigen::Index count = shares_[r].count;
    all_X.middleCols(shares_[r].first, count) = Eigen::Map<const Eigen::MatrixXd>(at, n, count);
    all_V.middleCols(shares_[r].first, count) = Eigen::Map<const Eigen::MatrixXd>(at + n * count, n, count);
  }
  // The whole ensemble in sigma order, as the CPU back end does it: the same bits on any R
  // (and any thread count).
  const Eigen::MatrixXd new_X = resampled_states_on(*pool_, all_X, recentering);
  const Eigen::MatrixXd new_V = resampled_states_on(*pool_, all_V, recentering);
  const ReplyLayout back(shares_, 0, 2 * static_cast<long>(n));
  std::vector<double> out(static_cast<std::size_t>(back.total));
  for (std::size_t r = 0; r < shares_.size(); ++r) {
    const Eigen::Index count = shares_[r].count;
    double* at = out.data() + back.offsets[r];
    Eigen::Map<Eigen::MatrixXd>(at, n, count) = new_X.middleCols(shares_[r].first, count);
    Eigen::Map<Eigen::MatrixXd>(at + n * count, n, count) = new_V.middleCols(shares_[r].first, count);
  }
  MPI_Scatterv(out.data(), back.counts.data(), back.offsets.data(), MPI_DOUBLE, MPI_IN_PLACE, 0, MPI_DOUBLE, 0,
               MPI_COMM_WORLD);
  if (own) std::rethrow_exception(own);
  if (failure.code != 0) failure.raise();
  const Eigen::Index count = shares_[0].count;
  local_->write_states(new_X.leftCols(count), new_V.leftCols(count));
  recenter_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void serve_ensemble(SimulationEnsemble& local, int sigma_count) {
  Worker worker{local, sigma_share(sigma_count, ranks().size, ranks().rank), nullptr, 0, ""};
  const int count = worker.share.count;
  const int p = local.parameter_count(), rows = local.observation_count();
  Eigen::Index n = 0;
  int advances = 0;
  {
    Eigen::MatrixXd X, V;
    local.read_states(X, V);   // agree_on_shares read them already: it does not fail here
    n = X.rows();
  }
  for (;;) {
    int header[2] = {0, 0};
    MPI_Bcast(header, 2, MPI_INT, 0, MPI_COMM_WORLD);
    switch (header[0]) {
      case kSetParameters: {
        Eigen::MatrixXd theta(p, sigma_count);
        MPI_Bcast(theta.data(), checked_count(theta.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
        worker.attempt([&] { local.set_parameters(theta.middleCols(worker.share.first, count)); });
        break;
      }
      case kAdvance: {
        Eigen::Vector3d so;
        MPI_Bcast(so.data(), 3, MPI_DOUBLE, 0, MPI_COMM_WORLD);
        std::vector<double> numbers(2 + 3 * static_cast<std::size_t>(count), 0.0);
        worker.attempt([&] {
          fail_if_asked(++advances);
          pack_report(local.advance(so), numbers);
        });
        worker.reply(numbers);
        break;
      }
      case kObservations: {
        std::vector<double> numbers(1 + static_cast<std::size_t>(rows) * count, 0.0);
        worker.attempt([&] {
          Eigen::MatrixXd y;
          local.predicted_observations(y);
          std::copy(y.data(), y.data() + y.size(), numbers.begin() + 1);
        });
        worker.reply(numbers);
        break;
      }
      case kRecenter: {
        const std::size_t size = static_cast<std::size_t>(n) * count;
        std::vector<double> numbers(1 + 2 * size, 0.0);
        worker.attempt([&] {
          Eigen::MatrixXd X, V;
          local.read_states(X, V);
          std::copy(X.data(), X.data() + X.size(), numbers.begin() + 1);
          std::copy(V.data(), V.data() + V.size(), numbers.begin() + 1 + static_cast<std::ptrdiff_t>(size));
        });
        worker.reply(numbers);
        std::vector<double> states(2 * size);
        MPI_Scatterv(nullptr, nullptr, nullptr, MPI_DOUBLE, states.data(), checked_count(static_cast<long>(states.size())),
                     MPI_DOUBLE, 0, MPI_COMM_WORLD);
        worker.attempt([&] {
          local.write_states(Eigen::Map<const Eigen::MatrixXd>(states.data(), n, count),
                             Eigen::Map<const Eigen::MatrixXd>(states.data() + size, n, count));
        });
        break;
      }
      case kStop: {
        std::string text;
        if (header[1] != 0) broadcast_text(text, 0);
        if (worker.failure) std::rethrow_exception(worker.failure);
        if (header[1] == 0) return;
        throw_as(header[1], text);
      }
      default:
        throw std::logic_error("serve_ensemble: unknown command " + std::to_string(header[0]));
    }
  }
}

void agree_on_shares(const std::exception_ptr& failure, const SimulationEnsemble* local, int sigma_count) {
  const RankInfo& world = ranks();
  std::exception_ptr own = failure;
  // Each rank's status, then what must be the same on every rank: S, the rank's share, p,
  // the observed rows and the state's rows.
  int mine[6] = {0, sigma_count, 0, 0, 0, 0};
  if (!own && local) {
    try {
      Eigen::MatrixXd X, V;
      local->read_states(X, V);
      mine[2] = local->sigma_count();
      mine[3] = local->parameter_count();
      mine[4] = local->observation_count();
      mine[5] = static_cast<int>(X.rows());
    } catch (...) {
      own = std::current_exception();
    }
  }
  std::string message;
  if (own) mine[0] = exit_code_of(own, message);
  std::vector<int> all(6 * static_cast<std::size_t>(world.size));
  MPI_Allgather(mine, 6, MPI_INT, all.data(), 6, MPI_INT, MPI_COMM_WORLD);
  for (int r = 0; r < world.size; ++r) {
    const int code = all[6 * static_cast<std::size_t>(r)];
    if (code == 0) continue;
    broadcast_text(message, r);   // the first failing rank's, on every rank
    if (own) std::rethrow_exception(own);
    throw_as(code, "rank " + std::to_string(r) + ": " + message);
  }
  auto describe = [&](int r) {
    const int* at = all.data() + 6 * r;
    return std::to_string(at[1]) + " sigma points (" + std::to_string(at[2]) + " on the rank), " +
           std::to_string(at[3]) + " parameters, " + std::to_string(at[4]) + " observed rows, " +
           std::to_string(at[5]) + " state rows";
  };
  for (int r = 0; r < world.size; ++r) {
    const int* at = all.data() + 6 * r;
    const bool same = at[1] == all[1] && at[3] == all[3] && at[4] == all[4] && at[5] == all[5] &&
                      at[2] == sigma_share(at[1], world.size, r).count;
    if (!same)
      throw InputError("rank " + std::to_string(r) + " runs another ensemble than rank 0: " + describe(r) +
                       " against " + describe(0) + "; every rank must run the same scenario, data and options");
  }
}

#else   // a build without MPI: ranks().size is always 1, and none of this is called

DistributedEnsemble::DistributedEnsemble(std::unique_ptr<SimulationEnsemble>, int) {
  throw std::logic_error("DistributedEnsemble: this sigmafem was built without MPI");
}
DistributedEnsemble::~DistributedEnsemble() = default;
void DistributedEnsemble::set_parameters(const Eigen::MatrixXd&) {}
StepReport DistributedEnsemble::advance(const Eigen::Vector3d&) { return {}; }
void DistributedEnsemble::predicted_observations(Eigen::MatrixXd&) const {}
void DistributedEnsemble::recenter(const Recentering&) {}
void DistributedEnsemble::stop(int, const std::string&) {}
void DistributedEnsemble::stop_after(const std::exception_ptr&) {}
void serve_ensemble(SimulationEnsemble&, int) {
  throw std::logic_error("serve_ensemble: this sigmafem was built without MPI");
}
void agree_on_shares(const std::exception_ptr&, const SimulationEnsemble*, int) {}
#endif

}  // namespace sigmafem
