#include "tmm/mesh/stl_io.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string_view>
#include <system_error>
#include <vector>

#include "tmm/util/parallel.hpp"

namespace tmm {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kHeaderBytes = 84;   // 80-byte header + uint32 triangle count
constexpr std::size_t kRecordBytes = 50;   // normal, 3 corners (12 float32), uint16 attribute
constexpr std::size_t kSniffBytes = 1024;  // prefix inspected to tell text from binary
// The shortest ASCII facet: "facet normal 0 0 0 outer loop", three "vertex 0 0 0", "endloop endfacet",
// single separators.
constexpr std::size_t kMinFacetBytes = 85;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

void read_exactly(std::FILE* f, void* dst, std::size_t bytes, const std::string& path) {
  if (bytes != 0 && std::fread(dst, 1, bytes, f) != bytes)
    throw StlError(path, std::ferror(f) ? "read error: " + std::string(std::strerror(errno))
                                        : std::string("file shrank while being read"));
}

uint32_t load_u32le(const unsigned char* b) {
  return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

float load_f32le(const unsigned char* b) {
  const uint32_t bits = load_u32le(b);  // compilers turn this into one load on little-endian machines
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

char lower(char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; }

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return lower(x) == y; });
}

bool istarts_with(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && iequals(s.substr(0, prefix.size()), prefix);
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// Control bytes other than whitespace never occur in an ASCII STL but are common in binary ones
// (zero bytes in counts, normals and attributes).
bool has_control_bytes(std::string_view s) {
  return std::any_of(s.begin(), s.end(), [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return (c < 0x20 && !is_space(ch)) || c == 0x7f;
  });
}

// Leading whitespace and a UTF-8 byte order mark are tolerated before "solid".
std::string_view skip_bom_and_space(std::string_view s) {
  if (s.substr(0, 3) == "\xEF\xBB\xBF") s.remove_prefix(3);
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  return s;
}

// A token as shown in messages: at most 40 characters, control bytes escaped.
std::string quoted(std::string_view tok) {
  std::string out = "'";
  for (std::size_t i = 0; i < tok.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(tok[i]);
    if (c < 0x20 || c == 0x7f) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\x%02x", c);
      out += esc;
    } else {
      out += char(c);
    }
  }
  return out + (tok.size() > 40 ? "...'" : "'");
}

// ---------------------------------------------------------------------------------------------------
// Binary

Soup read_binary(std::FILE* f, const std::string& path, uint64_t size, const unsigned char* head,
                 SerialProgress& progress) {
  if (size < kHeaderBytes)
    throw StlError(path, "file too short for an STL (" + std::to_string(size) +
                             " bytes; a binary STL needs an 84-byte header)");
  const uint32_t declared = load_u32le(head + 80);
  const uint64_t expected = kHeaderBytes + kRecordBytes * uint64_t(declared);
  const uint64_t holds = (size - kHeaderBytes) / kRecordBytes;
  if (size < expected)
    throw StlError(path, "binary STL declares " + std::to_string(declared) + " triangles but holds " +
                             std::to_string(holds) + " (file truncated?)");
  if (size > expected)
    throw StlError(path, "binary STL declares " + std::to_string(declared) + " triangles (" +
                             std::to_string(expected) + " bytes) but the file has " + std::to_string(size) +
                             " bytes (wrong count or extra data after the last triangle)");
  if (declared == 0) throw StlError(path, "binary STL holds no triangles");

  Soup soup(static_cast<Eigen::Index>(declared), 9);
  constexpr std::size_t kChunk = 1 << 15;  // triangles per read: a few MB, no per-triangle work beyond decoding
  std::vector<unsigned char> buf(kChunk * kRecordBytes);
  if (std::fseek(f, long(kHeaderBytes), SEEK_SET) != 0)
    throw StlError(path, "cannot seek: " + std::string(std::strerror(errno)));
  for (std::size_t first = 0; first < declared; first += kChunk) {
    progress.step(first, declared);
    const std::size_t count = std::min<std::size_t>(kChunk, declared - first);
    read_exactly(f, buf.data(), count * kRecordBytes, path);
    for (std::size_t i = 0; i < count; ++i) {
      const unsigned char* corners = buf.data() + i * kRecordBytes + 12;  // skip the normal
      double* row = soup.data() + (first + i) * 9;
      bool finite = true;
      for (int k = 0; k < 9; ++k) {
        const float x = load_f32le(corners + 4 * k);
        finite &= std::isfinite(x);
        row[k] = x;
      }
      if (!finite) {
        const std::size_t t = first + i;
        throw StlError(path, "triangle " + std::to_string(t) + " (byte offset " +
                                 std::to_string(kHeaderBytes + t * kRecordBytes) + ") has a non-finite coordinate");
      }
    }
  }
  return soup;
}

// ---------------------------------------------------------------------------------------------------
// ASCII: solid <name> { facet normal n n n  outer loop  (vertex x y z){3}  endloop  endfacet } endsolid <name>,
// possibly repeated. Tokens are separated by any whitespace; lines are counted for messages.

class AsciiParser {
 public:
  // Reports the share of the text parsed in progress's current part.
  AsciiParser(std::string_view text, const std::string& path, SerialProgress& progress)
      : begin_(text.data()), p_(begin_), end_(p_ + text.size()), path_(path), progress_(progress) {}

  Soup parse() {
    // Rows for as many facets as the text can hold, written in place and trimmed at the end (a shrinking
    // realloc; untouched rows cost address space only): a growing vector copies itself, and a gigabyte
    // file's triangles took seconds to copy without a report.
    Soup soup(Eigen::Index((end_ - p_) / kMinFacetBytes + 1), 9);
    Eigen::Index rows = 0;
    skip_space();
    if (end_ - p_ >= 3 && std::string_view(p_, 3) == "\xEF\xBB\xBF") p_ += 3;
    expect_solid(next());
    for (;;) {
      const std::string_view tok = next();
      if (iequals(tok, "facet")) {
        if (rows == soup.rows()) throw std::logic_error("ASCII STL: more facets than kMinFacetBytes allows");
        parse_facet(soup.row(rows++).data());
        progress_.tick(static_cast<std::size_t>(p_ - begin_), static_cast<std::size_t>(end_ - begin_));
      } else if (iequals(tok, "endsolid")) {
        skip_rest_of_line();  // the solid's name
        const std::string_view after = next();
        if (after.empty()) break;
        expect_solid(after);  // another solid follows
      } else {
        fail_expected("'facet' or 'endsolid'", tok);
      }
    }
    if (rows == 0) throw StlError(path_, "ASCII STL holds no triangles");
    soup.conservativeResize(rows, 9);
    return soup;
  }

 private:
  void skip_space() {
    for (; p_ < end_ && is_space(*p_); ++p_)
      if (*p_ == '\n' || (*p_ == '\r' && (p_ + 1 == end_ || p_[1] != '\n'))) ++line_;  // LF, CRLF or CR
  }

  void skip_rest_of_line() {
    while (p_ < end_ && *p_ != '\n' && *p_ != '\r') ++p_;
  }

  // The next token, or an empty view at the end of the text; tok_line_ is its line.
  std::string_view next() {
    skip_space();
    const char* start = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    if (p_ != start) tok_line_ = line_;
    tok_ = {start, std::size_t(p_ - start)};
    return tok_;
  }

  [[noreturn]] void fail(const std::string& problem) const {
    throw StlError(path_, "line " + std::to_string(tok_line_) + ": " + problem);
  }

  [[noreturn]] void fail_expected(const std::string& what, std::string_view got) const {
    if (got.empty())
      throw StlError(path_, "unexpected end of file after line " + std::to_string(tok_line_) + ", expected " + what +
                                " (file truncated?)");
    fail("expected " + what + ", got " + quoted(got));
  }

  void expect(std::string_view keyword) {
    const std::string_view tok = next();
    if (!iequals(tok, keyword)) fail_expected("'" + std::string(keyword) + "'", tok);
  }

  void expect_solid(std::string_view tok) {
    if (!istarts_with(tok, "solid")) fail_expected("'solid'", tok);
    skip_rest_of_line();  // the name, which may contain spaces
  }

  // The next token as a double; a value beyond the double range becomes infinity.
  double number(const char* what) {
    const std::string_view tok = next();
    const char* first = tok.data();
    const char* last = first + tok.size();
    if (last - first > 1 && *first == '+' && first[1] != '-') ++first;  // from_chars rejects a leading '+'
    double x = 0;
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (tok.empty() || ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range))
      fail_expected(std::string("a number (") + what + ")", tok);
    if (ec == std::errc::result_out_of_range) x = std::numeric_limits<double>::infinity();
    return x;
  }

  // Fills the 9 corner coordinates of `row`.
  void parse_facet(double* row) {
    expect("normal");
    for (int k = 0; k < 3; ++k) number("facet normal");  // not used: often zero or wrong, may be nan
    expect("outer");
    expect("loop");
    for (int v = 0; v < 3; ++v) {
      expect("vertex");
      for (int k = 0; k < 3; ++k) {
        const double x = number("vertex coordinate");
        if (!std::isfinite(x)) fail("non-finite vertex coordinate " + quoted(tok_));
        row[3 * v + k] = x;
      }
    }
    expect("endloop");
    expect("endfacet");
  }

  const char* begin_;
  const char* p_;
  const char* end_;
  const std::string& path_;
  SerialProgress& progress_;
  std::size_t line_ = 1;
  std::string_view tok_;      // the last token read
  std::size_t tok_line_ = 1;  // and its line
};

}  // namespace

namespace {

// Share of an ASCII read spent loading the text (the parse is the rest: tens of times slower).
constexpr double kTextLoadShare = 0.05;

// Reads the rest of the file into text[from, size) in blocks of a few tens of MB, so that a slow disk or
// a file of gigabytes reports progress and can be cancelled while it loads.
void read_text(std::FILE* f, char* text, std::size_t size, std::size_t from, const std::string& path,
               SerialProgress& progress) {
  constexpr std::size_t kBlock = std::size_t(8) << 20;
  for (std::size_t at = from; at < size; at += kBlock) {
    progress.step(at, size);
    read_exactly(f, text + at, std::min(kBlock, size - at), path);
  }
}

std::string file_kind(fs::file_type t) {
  switch (t) {
    case fs::file_type::fifo: return "a FIFO";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::socket: return "a socket";
    default: return "not a file";
  }
}

}  // namespace

Soup read_stl(const std::string& path, const std::function<bool(double)>& progress) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) throw StlError(path, "file not found");
  if (ec) throw StlError(path, "cannot access: " + ec.message());
  if (fs::is_directory(st)) throw StlError(path, "is a directory, not an STL file");
  // Only regular files: opening a FIFO blocks until a writer comes, a device (/dev/zero) never ends.
  if (!fs::is_regular_file(st)) throw StlError(path, "not a regular file (" + file_kind(st.type()) + ")");
  errno = 0;
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) throw StlError(path, "cannot open: " + std::string(std::strerror(errno)));
  const uint64_t size = fs::file_size(path, ec);
  if (ec) throw StlError(path, "cannot get the file size: " + ec.message());
  if (size == 0) throw StlError(path, "file is empty");

  unsigned char head[kSniffBytes];
  const std::size_t sniffed = std::size_t(std::min<uint64_t>(size, kSniffBytes));
  read_exactly(f.get(), head, sniffed, path);
  const std::string_view prefix(reinterpret_cast<const char*>(head), sniffed);

  // Binary when the size matches the declared count (binary headers often start with "solid" too).
  const bool size_fits_binary = size >= kHeaderBytes && size == kHeaderBytes + kRecordBytes * uint64_t(load_u32le(head + 80));
  const bool starts_solid = istarts_with(skip_bom_and_space(prefix), "solid");
  SerialProgress reporter(progress);
  if (size_fits_binary || has_control_bytes(prefix)) {
    Soup soup = read_binary(f.get(), path, size, head, reporter);
    reporter.finish();
    return soup;
  }
  if (!starts_solid)
    throw StlError(path, "not an STL file: text that does not start with 'solid' (starts with " +
                             quoted(skip_bom_and_space(prefix).substr(0, 20)) + ")");

  // Not zero-filled first: the blocks read fill it (a gigabyte memset would be a pause of its own).
  const auto length = static_cast<std::size_t>(size);
  const std::unique_ptr<char[]> text(new char[length]);
  std::memcpy(text.get(), head, sniffed);
  reporter.part(0.0, kTextLoadShare);
  read_text(f.get(), text.get(), length, sniffed, path, reporter);
  reporter.part(kTextLoadShare, 1.0);
  Soup soup = AsciiParser({text.get(), length}, path, reporter).parse();
  reporter.finish();
  return soup;
}

}  // namespace tmm
