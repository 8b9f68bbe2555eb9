// Batch work over many independent items (CL points, footprint points) on all cores, with progress and
// cancel: the one place that owns threads in the kernel.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <stdexcept>

namespace tmm {

// Thrown by batch calls when the progress callback asks to stop.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

class ChunkContext;

// The threads a batch takes when its caller names none: TMM_THREADS when set to a whole number from 1 up (a batch
// worker given one core of a shared machine), else every hardware thread.
int default_threads();

struct BatchOptions {
  int threads = 0;  // 0: default_threads()
  // Called now and then from the calling thread with the fraction done; return false to cancel. An
  // exception thrown by it (a Python KeyboardInterrupt) stops the batch and propagates.
  std::function<bool(double)> progress;
  // A batch run within a chunk of another (a waterline level among levels) stops when that one does:
  // throws Cancelled then.
  const ChunkContext* within = nullptr;
};

// What a long chunk sees of its batch: whether to stop early, and how far it has come (so that one chunk
// that is most of the work, a long move, still reports progress and can be cancelled within it).
class ChunkContext {
 public:
  ChunkContext(const std::atomic<bool>& stop, std::atomic<double>& partial, const ChunkContext* parent)
      : stop_(stop), partial_(partial), parent_(parent) {}
  // The batch is stopping (cancelled, or another chunk failed): return now, the results are thrown away.
  bool stopping() const {
    return stop_.load(std::memory_order_relaxed) || (parent_ != nullptr && parent_->stopping());
  }
  // For work deep in a call chain: leaves the chunk by throwing Cancelled (parallel_chunks then throws the
  // caller's Cancelled or the failing chunk's error).
  void throw_if_stopping() const {
    if (stopping()) throw Cancelled();
  }
  // Items of the current chunk done so far, fractional (progress only; reset when the chunk ends).
  void done_within(double items) { partial_.store(items, std::memory_order_relaxed); }

 private:
  const std::atomic<bool>& stop_;
  std::atomic<double>& partial_;
  const ChunkContext* parent_;
};

// Calls work(begin, end) for the fixed chunks [k * chunk, min(n, (k + 1) * chunk)) of [0, n), each exactly
// once, on options.threads threads. Chunks do not depend on the thread count, so work that depends only on
// its chunk gives the same results whatever the thread count. With a progress callback the calling thread
// only reports (a Python callback needs it) while workers compute, every 20 ms (a batch done sooner returns
// at once); its false cancels (throws
// Cancelled after the workers stop) and an exception from it stops the workers and propagates. The first
// exception thrown by `work` stops the others and is rethrown. Cancel is seen between chunks, and within a
// chunk by work taking a ChunkContext (the overload below) that checks stopping() between its sub-steps.
void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t begin, std::size_t end)>& work);
void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t begin, std::size_t end, ChunkContext& context)>& work);

// Progress and cancel of a loop on the calling thread (no workers): tick is a counter, looking at the clock
// every 256 calls and reporting at most every 20 ms; throws Cancelled when the callback says false. A job of
// several loops shares one: each loop runs in its part [lo, hi] of the job (part()) and reports its items
// done within it, so the fraction never goes back. A part's first look at the clock reports at once (a
// short loop reports too, and a cancel can be tested in each part without waiting for the clock).
class SerialProgress {
 public:
  explicit SerialProgress(const std::function<bool(double)>& progress) : progress_(progress) {}
  void tick(double fraction) {
    if (progress_ && (++calls_ & 255u) == 0) report(fraction);
  }
  // The loops that follow are the part [lo, hi] of the job.
  void part(double lo, double hi) {
    lo_ = lo;
    hi_ = hi;
    last_ = {};
  }
  // Item `done` of `total` of the current part (the fraction is only computed when reported).
  void tick(std::size_t done, std::size_t total) {
    if (progress_ && (++calls_ & 255u) == 0) report(within(done, total));
  }
  // For coarse steps (a millisecond or more each, a block read from a file): looks at the clock every call.
  void step(std::size_t done, std::size_t total) {
    if (progress_) report(within(done, total));
  }
  // The last report (1.0), the caller's last chance to cancel, as parallel_chunks gives it.
  void finish() {
    if (progress_ && !progress_(1.0)) throw Cancelled();
  }

 private:
  double within(std::size_t done, std::size_t total) const {
    return lo_ + (hi_ - lo_) * static_cast<double>(done) / static_cast<double>(total > 0 ? total : 1);
  }
  void report(double fraction);
  const std::function<bool(double)>& progress_;
  unsigned calls_ = 0;
  double lo_ = 0.0, hi_ = 1.0;
  std::chrono::steady_clock::time_point last_{};  // long ago: the first report is not held back
};

// The progress of a phase [lo, hi] of a longer job reported through `outer` (empty if outer is). Refers to
// outer, which must outlive the result (the caller's batch options).
std::function<bool(double)> progress_phase(const std::function<bool(double)>& outer, double lo, double hi);

}  // namespace tmm
