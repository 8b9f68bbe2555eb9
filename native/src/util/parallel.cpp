#include "tmm/util/parallel.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <condition_variable>
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

// The shared state of one parallel_chunks call.
struct Batch {
  std::size_t n, chunk, chunks;
  int threads;
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> cancel{false};
  std::unique_ptr<std::atomic<double>[]> partial;  // per worker: its chunk's items done (done_within)
  std::mutex mutex;                                 // guards error and exited
  std::condition_variable finished;                 // a worker exited
  std::exception_ptr error;
  int exited = 0;

  double fraction() const {
    double d = static_cast<double>(done.load());
    for (int t = 0; t < threads; ++t) d += partial[static_cast<std::size_t>(t)].load(std::memory_order_relaxed);
    return std::min(1.0, d / static_cast<double>(std::max<std::size_t>(n, 1)));
  }
};

void run_worker(Batch& b, int slot, const ChunkContext* parent,
                const std::function<void(std::size_t, std::size_t, ChunkContext&)>& work) {
  ChunkContext context(b.cancel, b.partial[static_cast<std::size_t>(slot)], parent);
  try {
    for (;;) {
      const std::size_t k = b.next.fetch_add(1);
      if (k >= b.chunks || context.stopping()) break;
      const std::size_t begin = k * b.chunk, end = std::min(b.n, begin + b.chunk);
      work(begin, end, context);
      context.done_within(0.0);
      b.done.fetch_add(end - begin);
    }
  } catch (...) {
    const std::lock_guard<std::mutex> lock(b.mutex);
    if (!b.error) b.error = std::current_exception();
    b.cancel.store(true);
  }
  {
    const std::lock_guard<std::mutex> lock(b.mutex);
    ++b.exited;
  }
  b.finished.notify_all();
}

// The calling thread's part while the workers run: a report every 20 ms until they have all exited.
// Returns false when the callback cancelled; an exception from it stops the workers and propagates.
bool report(Batch& b, const std::function<bool(double)>& progress) {
  double reported = 0.0;  // never backwards (a chunk's partial count and its end are two stores)
  try {
    std::unique_lock<std::mutex> lock(b.mutex);
    while (!b.finished.wait_for(lock, std::chrono::milliseconds(20), [&] { return b.exited == b.threads; })) {
      lock.unlock();
      reported = std::max(reported, b.fraction());
      const bool go_on = progress(reported);
      lock.lock();
      if (!go_on) {
        b.cancel.store(true);
        return false;
      }
    }
  } catch (...) {
    b.cancel.store(true);
    throw;
  }
  return true;
}

}  // namespace

int default_threads() {
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const char* named = std::getenv("TMM_THREADS");
  if (named == nullptr) return hardware;
  char* end = nullptr;
  const long n = std::strtol(named, &end, 10);
  return (end != named && *end == '\0' && n >= 1) ? static_cast<int>(std::min<long>(n, hardware)) : hardware;
}

void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t, std::size_t, ChunkContext&)>& work) {
  Batch b;
  b.n = n;
  b.chunk = std::max<std::size_t>(chunk, 1);
  b.chunks = (n + b.chunk - 1) / b.chunk;
  const int threads = options.threads > 0 ? options.threads : default_threads();
  b.threads = static_cast<int>(std::min<std::size_t>(threads, std::max<std::size_t>(b.chunks, 1)));
  b.partial = std::make_unique<std::atomic<double>[]>(static_cast<std::size_t>(b.threads));
  for (int t = 0; t < b.threads; ++t) b.partial[static_cast<std::size_t>(t)].store(0.0);
  bool cancelled_by_caller = false;
  {
    ThreadGroup group;
    const int first = options.progress ? 0 : 1;  // without a callback the calling thread works too
    for (int t = first; t < b.threads; ++t)
      group.spawn([&b, &options, &work, t] { run_worker(b, t, options.within, work); });
    if (options.progress) cancelled_by_caller = !report(b, options.progress);
    else run_worker(b, 0, options.within, work);
  }
  // A caller's cancel comes first: chunks that returned early on it may have left errors of their own.
  if (cancelled_by_caller || (options.within && options.within->stopping())) throw Cancelled();
  if (b.error) std::rethrow_exception(b.error);
  // The last report is the caller's last chance to cancel too (a batch done within the first poll
  // reports only this one).
  if (options.progress && !options.progress(1.0)) throw Cancelled();
}

void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t, std::size_t)>& work) {
  parallel_chunks(n, chunk, options, [&work](std::size_t b, std::size_t e, ChunkContext&) { work(b, e); });
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
