// The .npz writer (io/npz.h): .npy header layout and zip structure. The round trip through
// numpy itself is tests/cli/npz_round_trip.py (ctest cli.simulate_npz_round_trip).

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "io/npz.h"

namespace rlg::io {

using sim::Trace;

namespace {

uint64_t Le(const std::string& s, size_t at, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
  return v;
}

TEST(NpyHeader, HasMagicVersionAndA64BytePaddedDictWithTheShape) {
  for (uint64_t n : {0ull, 1ull, 86401ull, 123456789012ull}) {
    const std::string h = NpyHeader("<f8", n);
    EXPECT_EQ(h.substr(0, 6), "\x93NUMPY");
    EXPECT_EQ(h[6], 1);  // format version 1.0
    EXPECT_EQ(h[7], 0);
    const uint64_t len = Le(h, 8, 2);
    EXPECT_EQ(h.size(), 10 + len);
    EXPECT_EQ(h.size() % 64, 0u) << "data must start 64-byte aligned";
    EXPECT_EQ(h.back(), '\n');
    const std::string dict = h.substr(10, h.find('}') - 9);
    EXPECT_EQ(dict, "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(n) + ",), }");
    // Padding is spaces only.
    EXPECT_EQ(h.find_first_not_of(' ', 10 + dict.size()), h.size() - 1);
  }
}

TEST(NpzWriter, WritesStoredMembersAndACentralDirectoryThatFindsThem) {
  std::ostringstream out;
  const double values[3] = {1.5, -2.0, 1e-300};
  NpzWriter npz(out);
  npz.AddDoubles("run a/T1", values, 3);
  npz.AddStrings("runs", {"run a", "β"});
  npz.Finish();
  const std::string z = out.str();
  // First member: local header, its name, then the .npy bytes with the values unchanged.
  ASSERT_EQ(Le(z, 0, 4), 0x04034b50u);
  EXPECT_EQ(Le(z, 8, 2), 0u);  // stored, not compressed
  const uint64_t size = Le(z, 18, 4), name_len = Le(z, 26, 2), extra_len = Le(z, 28, 2);
  EXPECT_EQ(z.substr(30, name_len), "run a/T1.npy");
  const size_t npy = 30 + name_len + extra_len;
  const std::string header = NpyHeader("<f8", 3);
  EXPECT_EQ(size, header.size() + sizeof values);
  EXPECT_EQ(z.substr(npy, header.size()), header);
  EXPECT_EQ(std::memcmp(z.data() + npy + header.size(), values, sizeof values), 0);
  // End record: two entries, and the central directory where it says.
  const size_t end = z.size() - 22;
  ASSERT_EQ(Le(z, end, 4), 0x06054b50u);
  EXPECT_EQ(Le(z, end + 10, 2), 2u);
  const uint64_t cd_size = Le(z, end + 12, 4), cd_offset = Le(z, end + 16, 4);
  EXPECT_EQ(cd_offset + cd_size, end);
  EXPECT_EQ(Le(z, cd_offset, 4), 0x02014b50u);
  EXPECT_EQ(Le(z, cd_offset + 42, 4), 0u);  // first member's local header at 0
  // The strings member: '<U5' (the longest id), UTF-32 code points ("β" is U+03B2).
  const std::string u = NpyHeader("<U5", 2);
  const size_t second = z.find(u);
  ASSERT_NE(second, std::string::npos);
  EXPECT_EQ(Le(z, second + u.size(), 4), static_cast<uint64_t>('r'));
  EXPECT_EQ(Le(z, second + u.size() + 20, 4), 0x03B2u);
}

TEST(WriteTraceNpz, RefusesTwoRunsWithOneId) {
  Trace t;
  t.runs.resize(2);
  t.runs[0].id = t.runs[1].id = "a";
  std::ostringstream out;
  EXPECT_THROW(WriteTraceNpz(t, out), std::exception);
}

}  // namespace
}  // namespace rlg::io
