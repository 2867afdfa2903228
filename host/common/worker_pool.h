// WorkerPool: threads kept for the life of a CPU ensemble, so that each filter step hands its
// sigma points to waiting threads instead of starting and joining threads of its own (on the
// 596-tetrahedron liver a filter step is about a millisecond; two thread starts and joins per
// step were a tenth of it). The calling thread works too. Indices are taken in order as
// threads come free, so a sigma point whose factor is being made again does not hold up the
// ones queued behind it on the same thread; each index's work is the same whoever runs it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace sigmafem {

class WorkerPool {
 public:
  // `threads` in all, the caller's included (1: no pool thread, everything on the caller).
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Runs body(i) once for each i in 0..count-1 and returns when all are done; an exception
  // thrown by a body is rethrown here (the lowest index's) after the others finish.
  void run(int count, const std::function<void(int)>& body);

 private:
  void work();             // a pool thread's loop
  void take_indices();     // runs indices until none are left

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::uint64_t job_ = 0;       // counts run() calls: a pool thread wakes for a new one
  bool stopping_ = false;
  int busy_ = 0;                // pool threads still in the current job
  const std::function<void(int)>* body_ = nullptr;
  int count_ = 0;
  std::atomic<int> next_{0};
  std::vector<std::exception_ptr> errors_;   // by index
};

}  // namespace sigmafem
