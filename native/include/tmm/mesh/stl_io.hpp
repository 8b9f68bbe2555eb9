// Reading STL files (ASCII or binary) into a triangle soup.
#pragma once

#include "tmm/mesh/mesh.hpp"

#include <functional>
#include <stdexcept>
#include <string>

namespace tmm {

// A file that cannot be read or is not a valid STL. what() starts with the path and says where the
// problem is ("part.stl: line 12: expected 'vertex', got 'vertx'", "part.stl: triangle 17 (byte offset
// 934) has a non-finite coordinate").
class StlError : public std::runtime_error {
 public:
  StlError(const std::string& path, const std::string& problem)
      : std::runtime_error(path + ": " + problem), path_(path) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Reads the triangles of an STL file as an m x 9 soup (corners x1 y1 z1 x2 y2 z2 x3 y3 z3, m >= 1).
// Binary or ASCII is decided by content, not by the leading word: a file is binary when its size is
// exactly 84 + 50 * (declared count), or when it does not start with "solid" or has control bytes in
// its first kilobyte; otherwise it is ASCII. ASCII: keywords are case-insensitive, any line endings
// (LF, CRLF, CR), several solids per file allowed. Facet normals must be numbers but are not returned
// (they are often zero or wrong; compute them from the vertices). Binary: little-endian; normals and
// attribute bytes ignored.
// Throws StlError for a missing/unreadable file, a directory or anything else that is not a regular file
// (FIFO, device, socket: refused before opening), an empty file, no triangles, a truncated or garbled
// file, or a non-finite vertex coordinate.
// progress(fraction) is called now and then (tmm::SerialProgress: every 20 ms, and 1.0 at the end) from the
// calling thread; false cancels: throws tmm::Cancelled (a gigabyte ASCII file takes seconds to parse).
Soup read_stl(const std::string& path, const std::function<bool(double)>& progress = {});

}  // namespace tmm
