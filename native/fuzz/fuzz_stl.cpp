// libFuzzer harness of the STL reader (tmm/mesh/stl_io.hpp): any bytes as a file must give a soup of finite
// triangles or an StlError, never a crash, a sanitizer report or an unbounded allocation. read_stl takes a
// path, so each input is written to one in-memory file (memfd) read back through /proc/self/fd. Built by
// native/fuzz/CMakeLists.txt with clang (-fsanitize=fuzzer,address,undefined); run by scripts/test.sh over
// native/fuzz/corpus/stl for a bounded time.
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "tmm/mesh/stl_io.hpp"

namespace {

// The one file inputs are written to, created once.
class MemFile {
 public:
  MemFile() : fd_(memfd_create("fuzz.stl", 0)), path_("/proc/self/fd/" + std::to_string(fd_)) {
    if (fd_ < 0) std::abort();
  }
  ~MemFile() { close(fd_); }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  const std::string& write(const std::uint8_t* data, std::size_t size) {
    if (ftruncate(fd_, 0) != 0 || pwrite(fd_, data, size, 0) != static_cast<ssize_t>(size)) std::abort();
    return path_;
  }

 private:
  int fd_;
  std::string path_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static MemFile file;
  try {
    const tmm::Soup soup = tmm::read_stl(file.write(data, size));
    if (soup.rows() < 1 || !soup.allFinite()) std::abort();  // the reader's contract
  } catch (const tmm::StlError&) {
  }
  return 0;
}
