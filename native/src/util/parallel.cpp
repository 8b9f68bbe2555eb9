#include "tmm/util/parallel.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>
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
  parallel_chunks(n, chunk, options, [&work](std::size_t b, std::size_t e, ChunkContext&) { work(b, e); });
}

void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t, std::size_t, ChunkContext&)>& work) {
  chunk = std::max<std::size_t>(chunk, 1);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  int threads = options.threads > 0 ? options.threads
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::size_t>(threads, std::max<std::size_t>(chunks, 1)));
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> cancel{false};
  // Per worker: the items of its current chunk done so far (ChunkContext::done_within).
  const auto partial = std::make_unique<std::atomic<double>[]>(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) partial[static_cast<std::size_t>(t)].store(0.0);
  std::mutex error_mutex;
  std::exception_ptr error;
  auto worker = [&](int slot) {
    ChunkContext context(cancel, partial[static_cast<std::size_t>(slot)]);
    try {
      for (;;) {
        const std::size_t k = next.fetch_add(1);
        if (k >= chunks || cancel.load(std::memory_order_relaxed)) break;
        const std::size_t begin = k * chunk, end = std::min(n, begin + chunk);
        work(begin, end, context);
        context.done_within(0.0);
        done.fetch_add(end - begin);
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      cancel.store(true);
    }
  };
  auto fraction = [&] {
    double d = static_cast<double>(done.load());
    for (int t = 0; t < threads; ++t) d += partial[static_cast<std::size_t>(t)].load(std::memory_order_relaxed);
    return std::min(1.0, d / static_cast<double>(std::max<std::size_t>(n, 1)));
  };
  bool cancelled_by_caller = false;
  {
    ThreadGroup group;
    if (!options.progress) {
      for (int t = 1; t < threads; ++t) group.spawn([&worker, t] { worker(t); });
      worker(0);
    } else {
      for (int t = 0; t < threads; ++t) group.spawn([&worker, t] { worker(t); });
      try {
        double reported = 0.0;  // never backwards (a chunk's partial count and its end are two stores)
        while (done.load() < n && !cancel.load()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
          reported = std::max(reported, fraction());
          if (!options.progress(reported)) {
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
  // A caller's cancel comes first: chunks that returned early on it may have left errors of their own.
  if (cancelled_by_caller) throw Cancelled();
  if (error) std::rethrow_exception(error);
  // The last report is the caller's last chance to cancel too (a batch done within the first poll
  // reports only this one).
  if (options.progress && !options.progress(1.0)) throw Cancelled();
}

void SerialProgress::report(double fraction) {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(20)) return;
  last_ = now;
  if (!progress_(fraction)) throw Cancelled();
}

std::function<bool(double)> progress_phase(const std::function<bool(double)>& outer, double lo, double hi) {
  if (!outer) return {};
  return [&outer, lo, hi](double f) { return outer(lo + (hi - lo) * f); };
}

}  // namespace tmm
