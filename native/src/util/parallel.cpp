#include "tmm/util/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace tmm {

namespace {

// Joins its threads on every exit path.
class ThreadGroup {
 public:
  ~ThreadGroup() {
    for (auto& t : threads_) t.join();
  }
  template <class F>
  void spawn(F&& f) { threads_.emplace_back(std::forward<F>(f)); }

 private:
  std::vector<std::thread> threads_;
};

}  // namespace

void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t, std::size_t)>& work) {
  chunk = std::max<std::size_t>(chunk, 1);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  int threads = options.threads > 0 ? options.threads
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::size_t>(threads, std::max<std::size_t>(chunks, 1)));
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> cancel{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  auto worker = [&] {
    try {
      for (;;) {
        const std::size_t k = next.fetch_add(1);
        if (k >= chunks || cancel.load(std::memory_order_relaxed)) break;
        const std::size_t begin = k * chunk, end = std::min(n, begin + chunk);
        work(begin, end);
        done.fetch_add(end - begin);
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      cancel.store(true);
    }
  };
  bool cancelled_by_caller = false;
  {
    ThreadGroup group;
    if (!options.progress) {
      for (int t = 1; t < threads; ++t) group.spawn(worker);
      worker();
    } else {
      for (int t = 0; t < threads; ++t) group.spawn(worker);
      try {
        while (done.load() < n && !cancel.load()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
          if (!options.progress(static_cast<double>(done.load()) / static_cast<double>(n))) {
            cancelled_by_caller = true;
            cancel.store(true);
          }
        }
      } catch (...) {
        cancel.store(true);
        throw;
      }
    }
  }
  if (error) std::rethrow_exception(error);
  // The last report is the caller's last chance to cancel too (a batch done within the first poll
  // reports only this one).
  if (cancelled_by_caller || (options.progress && !options.progress(1.0))) throw Cancelled();
}

}  // namespace tmm
