// Threads kept for a renderer's lifetime, so that a live frame starts none:
// run() hands the items 0..count-1 out one at a time (rows of an image, as the
// CPU reference does, so a row's samples never depend on the thread count)
// and returns when all are done. The calling thread works too.
//
// Thread safety: one thread calls run() at a time.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace camhead::renderer {

class WorkerPool {
public:
  // threads <= 0: one per hardware thread. Throws std::system_error when a
  // thread cannot be started (the threads started so far are joined).
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool &) = delete;
  WorkerPool &operator=(const WorkerPool &) = delete;

  [[nodiscard]] int threads() const { return int(workers_.size()) + 1; }

  // Calls task(i) for every i in [0, count), spread over the threads. The
  // task must not throw.
  template <typename Task> void run(int count, Task &task) {
    run_erased(count, &task, [](void *t, int i) { (*static_cast<Task *>(t))(i); });
  }

private:
  using Trampoline = void (*)(void *, int);
  void run_erased(int count, void *task, Trampoline call);
  void work(); // the items of the current job until none is left
  void worker_loop();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  std::uint64_t generation_ = 0; // bumped per job
  bool stopping_ = false;
  int busy_ = 0; // workers still inside the current job
  void *task_ = nullptr;
  Trampoline call_ = nullptr;
  int count_ = 0;
  std::atomic<int> next_{0};
};

} // namespace camhead::renderer
