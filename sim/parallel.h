// A small persistent thread pool for the per-body and per-pair stages. Work is split into contiguous chunks by
// index and every result goes to its own slot, so results do not depend on the number of threads.
#pragma once
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace floesim::sim {

class ThreadPool {
 public:
  explicit ThreadPool(int threads) : threads_(threads < 1 ? 1 : threads) {
    for (int w = 1; w < threads_; ++w) workers_.emplace_back([this, w] { loop(w); });
  }
  ~ThreadPool() {
    {
      std::lock_guard<std::mutex> lk(m_);
      stop_ = true;
      ++generation_;
    }
    cv_.notify_all();
    for (auto& t : workers_) t.join();
  }
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int threads() const { return threads_; }

  // Calls fn(begin, end, worker) for `threads` contiguous chunks of [0, n) and returns when all are done.
  // Small jobs run on the calling thread.
  void parallel_for(int n, const std::function<void(int, int, int)>& fn, int min_per_thread = 16) {
    if (threads_ == 1 || n < 2 * min_per_thread) {
      if (n > 0) fn(0, n, 0);
      return;
    }
    {
      std::lock_guard<std::mutex> lk(m_);
      job_ = &fn;
      n_ = n;
      pending_ = threads_ - 1;
      ++generation_;
    }
    cv_.notify_all();
    run_chunk(0);
    std::unique_lock<std::mutex> lk(m_);
    done_cv_.wait(lk, [this] { return pending_ == 0; });
    job_ = nullptr;
  }

 private:
  void run_chunk(int w) {
    const int b = static_cast<int>(static_cast<long>(n_) * w / threads_);
    const int e = static_cast<int>(static_cast<long>(n_) * (w + 1) / threads_);
    if (e > b) (*job_)(b, e, w);
  }
  void loop(int w) {
    long seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lk(m_);
        cv_.wait(lk, [&] { return generation_ != seen; });
        seen = generation_;
        if (stop_) return;
      }
      run_chunk(w);
      {
        std::lock_guard<std::mutex> lk(m_);
        --pending_;
      }
      done_cv_.notify_one();
    }
  }

  int threads_;
  std::vector<std::thread> workers_;
  std::mutex m_;
  std::condition_variable cv_, done_cv_;
  const std::function<void(int, int, int)>* job_ = nullptr;
  int n_ = 0, pending_ = 0;
  long generation_ = 0;
  bool stop_ = false;
};

}  // namespace floesim::sim
