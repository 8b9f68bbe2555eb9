// Batch work over many independent items (CL points, footprint points) on all cores, with progress and
// cancel: the one place that owns threads in the kernel.
#pragma once

#include <cstddef>
#include <functional>
#include <stdexcept>

namespace tmm {

// Thrown by batch calls when the progress callback asks to stop.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

struct BatchOptions {
  int threads = 0;  // 0: all hardware threads
  // Called now and then from the calling thread with the fraction done; return false to cancel.
  std::function<bool(double)> progress;
};

// Calls work(begin, end) for the fixed chunks [k * chunk, min(n, (k + 1) * chunk)) of [0, n), each exactly
// once, on options.threads threads. Chunks do not depend on the thread count, so work that depends only on
// its chunk gives the same results whatever the thread count. With a progress callback the calling thread
// only reports (a Python callback needs it) while workers compute; its false cancels (throws Cancelled
// after the workers stop) and an exception from it stops the workers and propagates. The first exception
// thrown by `work` stops the others and is rethrown.
void parallel_chunks(std::size_t n, std::size_t chunk, const BatchOptions& options,
                     const std::function<void(std::size_t begin, std::size_t end)>& work);

}  // namespace tmm
