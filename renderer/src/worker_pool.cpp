#include "worker_pool.h"

#include <algorithm>

#include "camhead/base/thread_name.h"

namespace camhead::renderer {

WorkerPool::WorkerPool(int threads) {
  if (threads <= 0)
    threads = int(std::max(1u, std::thread::hardware_concurrency()));
  workers_.reserve(std::size_t(threads - 1));
  try {
    for (int t = 1; t < threads; ++t)
      workers_.emplace_back([this] {
        base::name_this_thread("camhead-worker");
        worker_loop();
      });
  } catch (...) {
    // A vector of joinable threads must not be destroyed: stop the ones
    // that started before giving the error on.
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    start_.notify_all();
    for (std::thread &worker : workers_)
      worker.join();
    throw;
  }
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (std::thread &worker : workers_)
    worker.join();
}

void WorkerPool::work() {
  for (int i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1))
    call_(task_, i);
}

void WorkerPool::worker_loop() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      start_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_)
        return;
      seen = generation_;
    }
    work();
    {
      std::lock_guard lock(mutex_);
      --busy_;
    }
    done_.notify_one();
  }
}

void WorkerPool::run_erased(int count, void *task, Trampoline call) {
  {
    std::lock_guard lock(mutex_);
    task_ = task;
    call_ = call;
    count_ = count;
    next_ = 0;
    busy_ = int(workers_.size());
    ++generation_;
  }
  start_.notify_all();
  work();
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return busy_ == 0; });
}

} // namespace camhead::renderer
