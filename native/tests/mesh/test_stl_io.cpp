// STL reading: ASCII and binary by content, line endings, normals ignored, and every way a file can be
// broken, each reported with the file and the place.
#include "tmm/mesh/stl_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <string>
#include <vector>

#include "support/progress_checks.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

// A fresh directory per test, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("tmm_stl_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string file(const std::string& name, const std::string& bytes) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

// The message of the StlError that reading `path` throws ("" and a test failure when none is thrown).
std::string read_error(const std::string& path) {
  try {
    tmm::read_stl(path);
  } catch (const tmm::StlError& e) {
    EXPECT_EQ(e.path(), path);
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an StlError: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error reading " << path;
  return {};
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

using Tri = std::array<float, 9>;

std::string ascii_facet(const Tri& t, const std::string& normal = "0 0 1", const std::string& eol = "\n") {
  std::string s = "  facet normal " + normal + eol + "    outer loop" + eol;
  for (int v = 0; v < 3; ++v) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "      vertex %.17g %.17g %.17g", double(t[3 * v]), double(t[3 * v + 1]),
                  double(t[3 * v + 2]));
    s += buf + eol;
  }
  return s + "    endloop" + eol + "  endfacet" + eol;
}

std::string ascii_stl(const std::vector<Tri>& tris, const std::string& eol = "\n") {
  std::string s = "solid test" + eol;
  for (const Tri& t : tris) s += ascii_facet(t, "0 0 1", eol);
  return s + "endsolid test" + eol;
}

void put_u32(std::string& s, uint32_t x) {
  for (int i = 0; i < 4; ++i) s += char((x >> (8 * i)) & 0xff);
}
void put_f32(std::string& s, float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  put_u32(s, bits);
}

std::string binary_stl(const std::vector<Tri>& tris, std::string header = "binary test",
                       int64_t declared = -1) {
  header.resize(80, ' ');
  std::string s = header;
  put_u32(s, declared < 0 ? uint32_t(tris.size()) : uint32_t(declared));
  for (const Tri& t : tris) {
    for (int k = 0; k < 3; ++k) put_f32(s, std::numeric_limits<float>::quiet_NaN());  // normals: ignored
    for (float x : t) put_f32(s, x);
    s += "\x12\x34";  // attribute bytes: ignored
  }
  return s;
}

const std::vector<Tri> kTris = {
    Tri{0, 0, 0, 1, 0, 0, 0, 1, 0},
    Tri{1, 0, 0, 1, 1, 0, 0, 1, 0},
    Tri{-1.5f, 2.25f, 1e-3f, 3e4f, -7.125f, 0.5f, 1, 2, 3},
};

void expect_soup(const tmm::Soup& soup, const std::vector<Tri>& tris) {
  ASSERT_EQ(soup.rows(), Eigen::Index(tris.size()));
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 9; ++k) EXPECT_EQ(soup(Eigen::Index(t), k), double(tris[t][std::size_t(k)])) << t << "," << k;
}

}  // namespace

TEST(StlRead, SharedBenchmarkFiles) {
  struct Case {
    const char* name;
    Eigen::Index triangles;
  };
  for (const Case& c : {Case{"beet_mm.stl", 4630}, Case{"demo.stl", 1894}, Case{"ktoolcav.stl", 4090},
                        Case{"mount_rush.stl", 15592}, Case{"pycam-textbox.stl", 1444},
                        Case{"sphere_on_plate.stl", 7570}, Case{"wheel_in_box.stl", 6102}}) {
    const std::string path = std::string(TMM_SHARED_STL_DIR) + "/" + c.name;
    tmm::Soup soup;
    ASSERT_NO_THROW(soup = tmm::read_stl(path)) << path;
    EXPECT_EQ(soup.rows(), c.triangles) << c.name;
    EXPECT_TRUE(soup.allFinite()) << c.name;
  }
}

TEST(StlRead, SharedFilesDetectedByContent) {
  // ktoolcav.stl is binary although its header starts with "solid"; demo.stl is ASCII with CRLF;
  // beet_mm.stl is ASCII with zero facet normals.
  const std::string dir = TMM_SHARED_STL_DIR;
  std::ifstream k(dir + "/ktoolcav.stl", std::ios::binary);
  std::string head(5, '\0');
  k.read(head.data(), 5);
  ASSERT_EQ(head, "solid");
  EXPECT_EQ(tmm::read_stl(dir + "/ktoolcav.stl").rows(), 4090);
}

TEST(StlRead, Ascii) {
  TempDir tmp;
  expect_soup(tmm::read_stl(tmp.file("a.stl", ascii_stl(kTris))), kTris);
}

TEST(StlRead, AsciiCrlfAndCr) {
  TempDir tmp;
  expect_soup(tmm::read_stl(tmp.file("crlf.stl", ascii_stl(kTris, "\r\n"))), kTris);
  expect_soup(tmm::read_stl(tmp.file("cr.stl", ascii_stl(kTris, "\r"))), kTris);
}

TEST(StlRead, AsciiLenientSyntax) {
  TempDir tmp;
  // Keywords in any case, tabs, '+' signs, exponents, a nameless solid, a second solid, no final newline.
  const std::string text =
      "\xEF\xBB\xBF  solid\n"
      "FACET NORMAL 0 0 0\n OUTER LOOP\n\tVERTEX +0 0e0 0.0\n vertex 1.0E+000 0 0\n"
      " vertex 0 1 -0\n ENDLOOP\n ENDFACET\nENDSOLID\n"
      "solid second part\nfacet normal nan -inf 1e999\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n"
      "vertex 0 1 0\nendloop\nendfacet\nendsolid second part";
  expect_soup(tmm::read_stl(tmp.file("lenient.stl", text)), {kTris[0], kTris[1]});
}

TEST(StlRead, WrongAndZeroNormalsIgnored) {
  TempDir tmp;
  std::string text = "solid x\n";
  text += ascii_facet(kTris[0], "0 0 0");
  text += ascii_facet(kTris[1], "0 0 -1");      // opposite to the winding
  text += ascii_facet(kTris[2], "-nan nan 7");  // some exporters write this for slivers
  text += "endsolid x\n";
  expect_soup(tmm::read_stl(tmp.file("normals.stl", text)), kTris);
}

TEST(StlRead, Binary) {
  TempDir tmp;
  expect_soup(tmm::read_stl(tmp.file("b.stl", binary_stl(kTris))), kTris);
}

TEST(StlRead, BinaryWithSolidHeader) {
  TempDir tmp;
  // The 80-byte header is text starting with "solid" (as many exporters write it).
  expect_soup(tmm::read_stl(tmp.file("b.stl", binary_stl(kTris, "solid looks like ascii"))), kTris);
  // Same, with a size that does not match: the control bytes after the header still say binary.
  const std::string path = tmp.file("bt.stl", binary_stl(kTris, "solid looks like ascii", 5));
  EXPECT_CONTAINS(read_error(path), "binary STL declares 5 triangles but holds 3 (file truncated?)");
}

TEST(StlRead, BinaryTruncated) {
  TempDir tmp;
  std::vector<Tri> tris(812, kTris[2]);
  std::string bytes = binary_stl(tris, "x", 1000) + std::string(17, '\0');  // 812 and a partial record
  const std::string path = tmp.file("part.stl", bytes);
  EXPECT_EQ(read_error(path), path + ": binary STL declares 1000 triangles but holds 812 (file truncated?)");
}

TEST(StlRead, BinaryExtraData) {
  TempDir tmp;
  const std::string path = tmp.file("extra.stl", binary_stl(kTris, "x", 2));
  const std::string msg = read_error(path);
  EXPECT_CONTAINS(msg, path + ": binary STL declares 2 triangles (184 bytes) but the file has 234 bytes");
}

TEST(StlRead, BinaryNonFinite) {
  TempDir tmp;
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()}) {
    std::vector<Tri> tris(20, kTris[0]);
    tris[17][4] = bad;
    const std::string path = tmp.file("nan.stl", binary_stl(tris));
    EXPECT_EQ(read_error(path), path + ": triangle 17 (byte offset 934) has a non-finite coordinate");
  }
}

TEST(StlRead, BinaryNoTriangles) {
  TempDir tmp;
  const std::string path = tmp.file("zero.stl", binary_stl({}));
  EXPECT_EQ(read_error(path), path + ": binary STL holds no triangles");
}

TEST(StlRead, BinaryTooShort) {
  TempDir tmp;
  const std::string path = tmp.file("short.stl", std::string("\x01\x02\x03 abc", 7));
  EXPECT_CONTAINS(read_error(path), path + ": file too short for an STL (7 bytes");
}

TEST(StlRead, AsciiGarbledKeyword) {
  TempDir tmp;
  std::string text = ascii_stl(kTris);
  // Line 12 is the second vertex of the second facet.
  const std::size_t at = text.find("vertex 1 1 0");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 6, "vertx");
  for (const char* eol : {"\n", "\r\n"}) {
    std::string t = text;
    if (std::string(eol) == "\r\n")
      for (std::size_t i = t.find('\n'); i != std::string::npos; i = t.find('\n', i + 2)) t.insert(i, "\r");
    const std::string path = tmp.file("part.stl", t);
    EXPECT_EQ(read_error(path), path + ": line 12: expected 'vertex', got 'vertx'") << "eol length " << std::strlen(eol);
  }
}

TEST(StlRead, AsciiGarbledNumber) {
  TempDir tmp;
  std::string text = ascii_stl(kTris);
  text.replace(text.find("vertex 1 1 0"), 12, "vertex 1 1.0.0 0");
  const std::string path = tmp.file("num.stl", text);
  EXPECT_EQ(read_error(path), path + ": line 12: expected a number (vertex coordinate), got '1.0.0'");
}

TEST(StlRead, AsciiGarbledTopLevel) {
  TempDir tmp;
  const std::string path = tmp.file("top.stl", ascii_stl(kTris) + "garbage\n");  // endsolid is line 23
  EXPECT_EQ(read_error(path), path + ": line 24: expected 'solid', got 'garbage'");
  const std::string path2 = tmp.file("top2.stl", "solid a\n  facet normal 0 0 1\n  outer loop\nendsolid a\n");
  EXPECT_EQ(read_error(path2), path2 + ": line 4: expected 'vertex', got 'endsolid'");
}

TEST(StlRead, AsciiNonFinite) {
  TempDir tmp;
  for (const char* bad : {"nan", "-inf", "inf", "1e999", "-1E+400"}) {
    std::string text = ascii_stl(kTris);
    text.replace(text.find("vertex 1 1 0"), 12, std::string("vertex 1 ") + bad + " 0");
    const std::string path = tmp.file("nan.stl", text);
    EXPECT_EQ(read_error(path), path + ": line 12: non-finite vertex coordinate '" + bad + "'");
  }
}

TEST(StlRead, AsciiTruncated) {
  TempDir tmp;
  const std::string text = ascii_stl(kTris);
  // Cut in the middle of line 12 ("      vertex 1 1 0"): the last token read is "1" on line 12.
  const std::string path = tmp.file("cut.stl", text.substr(0, text.find("vertex 1 1 0") + 10));
  EXPECT_EQ(read_error(path), path + ": unexpected end of file after line 12, expected a number (vertex coordinate) "
                                     "(file truncated?)");
  // Cut after a complete facet: no endsolid.
  const std::string path2 = tmp.file("cut2.stl", text.substr(0, text.find("endsolid")));
  EXPECT_EQ(read_error(path2),
            path2 + ": unexpected end of file after line 22, expected 'facet' or 'endsolid' (file truncated?)");
}

TEST(StlRead, AsciiNoTriangles) {
  TempDir tmp;
  const std::string path = tmp.file("none.stl", "solid empty\nendsolid empty\n");
  EXPECT_EQ(read_error(path), path + ": ASCII STL holds no triangles");
}

TEST(StlRead, EmptyMissingDirectoryAndNotStl) {
  TempDir tmp;
  const std::string empty = tmp.file("empty.stl", "");
  EXPECT_EQ(read_error(empty), empty + ": file is empty");
  const std::string missing = tmp.path("missing.stl");
  EXPECT_EQ(read_error(missing), missing + ": file not found");
  const std::string dir = tmp.path("");
  EXPECT_CONTAINS(read_error(dir), "is a directory");
  const std::string text = tmp.file("text.stl", "hello world, this is not an STL file at all\n");
  EXPECT_EQ(read_error(text), text + ": not an STL file: text that does not start with 'solid' "
                                     "(starts with 'hello world, this is')");
}

// 5 million triangles (250 MB): read in one pass with no per-triangle allocation. Timing belongs in
// the benchmarks; this only checks it completes and decodes correctly.
TEST(StlRead, BigBinary) {
  TempDir tmp;
  constexpr uint32_t kCount = 5'000'000;
  const std::string path = tmp.path("big.stl");
  {
    std::ofstream out(path, std::ios::binary);
    std::string header(80, ' ');
    header.replace(0, 9, "solid big");
    put_u32(header, kCount);
    out << header;
    constexpr uint32_t kChunk = 65536;
    std::vector<char> chunk(50 * std::size_t(kChunk), '\0');  // normals and attributes stay zero
    for (uint32_t first = 0; first < kCount; first += kChunk) {
      const uint32_t n = std::min(kChunk, kCount - first);
      for (uint32_t i = 0; i < n; ++i) {
        const uint32_t t = first + i;
        const float x = float(t % 4096), y = float(t / 4096);
        const float corners[9] = {x, y, 0.0f, x + 1, y, 0.5f, x, y + 1, 1.0f};
        std::memcpy(chunk.data() + 50 * std::size_t(i) + 12, corners, sizeof corners);  // little-endian host
      }
      out.write(chunk.data(), std::streamsize(50 * std::size_t(n)));
    }
  }
  ASSERT_EQ(fs::file_size(path), 84u + 50u * kCount);
  const tmm::Soup soup = tmm::read_stl(path);
  ASSERT_EQ(soup.rows(), Eigen::Index(kCount));
  for (uint32_t t : {0u, 4097u, kCount / 2, kCount - 1}) {
    EXPECT_EQ(soup(t, 0), double(t % 4096));
    EXPECT_EQ(soup(t, 1), double(t / 4096));
    EXPECT_EQ(soup(t, 3), double(t % 4096 + 1));
    EXPECT_EQ(soup(t, 8), 1.0);
  }
}

namespace {

TEST(StlRead, NotARegularFileIsRefusedAtOnce) {
  TempDir tmp;
  const std::string fifo = tmp.path("pipe.stl");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // Opening a FIFO for reading blocks until a writer comes: read on a thread, and if it has not returned
  // after a second, be the writer (so the test fails instead of hanging).
  auto reading = std::async(std::launch::async, [&] { return read_error(fifo); });
  if (reading.wait_for(std::chrono::seconds(1)) != std::future_status::ready) {
    ADD_FAILURE() << "read_stl blocked on a FIFO";
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd >= 0) ::close(fd);
  }
  EXPECT_EQ(reading.get(), fifo + ": not a regular file (a FIFO)");
  EXPECT_EQ(read_error("/dev/zero"), "/dev/zero: not a regular file (a character device)");
}

}  // namespace

// Reading reports progress (ASCII: by the text parsed; binary: by blocks of triangles), a cancel at the
// first report stops it, and a callback that goes on changes nothing.
TEST(StlRead, ReportsProgressAndCancels) {
  TempDir tmp;
  std::vector<Tri> tris;
  for (int i = 0; i < 3000; ++i)  // enough facets for an ASCII report before the last
    tris.push_back(Tri{float(i), 0, 0, float(i) + 1, 0, 0, float(i), 1, float(i % 7)});
  for (const std::string& path : {tmp.file("a.stl", ascii_stl(tris)), tmp.file("b.stl", binary_stl(tris))}) {
    const tmm::Soup soup =
        tmm_test::run_reported([&](const tmm_test::ProgressFn& p) { return tmm::read_stl(path, p); });
    EXPECT_EQ(soup, tmm::read_stl(path)) << path;
    expect_soup(soup, tris);
  }
}
