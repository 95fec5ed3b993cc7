// A small persistent thread pool for the per-body and per-pair stages. Work is split into chunks by index and
// every result goes to its own slot (per index, or per chunk: parallel_chunks), so results do not depend on the
// number of threads or on which thread ran what.
//
// A step hands the pool five short jobs (poses, narrow phase, forces, solve, relax) of 0.05-1 ms each, with serial
// work between them. Waking a thread blocked on a condition variable takes tens of microseconds (a futex call and a
// reschedule), as long as a job's work: with two threads the stages ran no faster than with one. So a thread that
// has finished a job first spins for a while (kSpinNs) on the job counter, yielding its core to anything else that
// wants it, and only then blocks; the caller waits for the others the same way. The spin outlasts the serial work
// between two jobs, the longest of which is the bow island's solve and relax (one island, one thread: 0.4 ms on
// the bench's fields, ~0.8 ms in the 660 s crossing). With a 0.2 ms spin the helper fell asleep there in most
// steps and the next step's first jobs (poses, narrow phase) waited on its wake-up: on versus-box2d's seed 2 (two
// threads, 20,000 steps) 15,445 context switches and 55,158 futex calls per run, against 1,268 and 14,211 with
// 2 ms, for 1.6 % more CPU time and a few per cent less wall time at most (README "Benchmark"). So between the
// steps of a running simulation a thread is seldom asleep; between runs (or under a foreign load) it sleeps.
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
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
      generation_.fetch_add(1, std::memory_order_release);
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
    job_ = &fn;
    n_ = n;
    pending_.store(threads_ - 1, std::memory_order_relaxed);
    {
      // Under the lock, so that a thread about to block sees either the old counter and is woken, or the new one.
      std::lock_guard<std::mutex> lk(m_);
      generation_.fetch_add(1, std::memory_order_release);
    }
    cv_.notify_all();  // no system call when nobody is blocked
    run_chunk(0);
    if (!spin_until([this] { return pending_.load(std::memory_order_acquire) == 0; })) {
      std::unique_lock<std::mutex> lk(m_);
      done_cv_.wait(lk, [this] { return pending_.load(std::memory_order_acquire) == 0; });
    }
    job_ = nullptr;
  }

  // Calls fn(begin, end, worker, chunk) for the chunks [chunk * grain, ...) of [0, n), handed out one at a time to
  // whichever thread is free (for work of uneven cost per index: the bow's rubble sits in one range of the sorted
  // pairs). Which thread runs a chunk varies from run to run: fn must write its results by chunk, not by worker.
  void parallel_chunks(int n, int grain, const std::function<void(int, int, int, int)>& fn) {
    const int chunks = (n + grain - 1) / grain;
    if (threads_ == 1 || chunks < 2) {
      for (int k = 0; k < chunks; ++k) fn(k * grain, std::min(n, (k + 1) * grain), 0, k);
      return;
    }
    next_chunk_.store(0, std::memory_order_relaxed);
    const std::function<void(int, int, int)> take = [&](int, int, int w) {
      for (int k; (k = next_chunk_.fetch_add(1, std::memory_order_relaxed)) < chunks;)
        fn(k * grain, std::min(n, (k + 1) * grain), w, k);
    };
    parallel_for(threads_, take, 1);
  }

 private:
  static constexpr std::chrono::nanoseconds kSpinNs{2'000'000};  // see the top of the file

  // Polls `ready` for up to kSpinNs, yielding the core between polls; returns whether it became true.
  template <class Pred>
  static bool spin_until(Pred ready) {
    if (ready()) return true;
    const auto until = std::chrono::steady_clock::now() + kSpinNs;
    for (;;) {
      for (int i = 0; i < 64; ++i) {
        if (ready()) return true;
#if defined(__x86_64__) || defined(__i386__)
        __builtin_ia32_pause();
#endif
      }
      if (std::chrono::steady_clock::now() >= until) return ready();
      std::this_thread::yield();
    }
  }

  void run_chunk(int w) {
    const int b = static_cast<int>(static_cast<long>(n_) * w / threads_);
    const int e = static_cast<int>(static_cast<long>(n_) * (w + 1) / threads_);
    if (e > b) (*job_)(b, e, w);
  }
  void loop(int w) {
    long seen = 0;
    for (;;) {
      auto fresh = [&] { return generation_.load(std::memory_order_acquire) != seen; };
      if (!spin_until(fresh)) {
        std::unique_lock<std::mutex> lk(m_);
        cv_.wait(lk, fresh);
      }
      seen = generation_.load(std::memory_order_acquire);
      {
        std::lock_guard<std::mutex> lk(m_);
        if (stop_) return;
      }
      run_chunk(w);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
        std::lock_guard<std::mutex> lk(m_);  // the caller may be between its check and its wait
        done_cv_.notify_one();
      }
    }
  }
  int threads_;
  std::vector<std::thread> workers_;
  std::mutex m_;
  std::condition_variable cv_, done_cv_;
  const std::function<void(int, int, int)>* job_ = nullptr;
  int n_ = 0;
  std::atomic<int> pending_{0};
  std::atomic<int> next_chunk_{0};
  std::atomic<long> generation_{0};
  bool stop_ = false;
};

}  // namespace floesim::sim
