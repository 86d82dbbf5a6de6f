#include "io/npz.h"

#include <algorithm>
#include <fmt/format.h>
#include <set>
#include <zlib.h>

#include "sim/errors.h"

namespace rlg::io {

using sim::Run;
using sim::Trace;

namespace {

bool LittleEndian() {
  const uint16_t one = 1;
  return *reinterpret_cast<const unsigned char*>(&one) == 1;
}

// Zip and .npy length fields are little-endian whatever the machine.
void PutLe(std::string& s, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

// UTF-8 to code points; a malformed byte becomes U+FFFD (run ids are checked text anyway).
std::u32string DecodeUtf8(const std::string& s) {
  std::u32string out;
  for (size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    const int len = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    char32_t c = len == 1 ? b : len == 2 ? (b & 0x1F) : len == 3 ? (b & 0x0F) : (b & 0x07);
    bool ok = len > 0 && i + len <= s.size();
    for (int k = 1; ok && k < len; ++k) {
      const auto cont = static_cast<unsigned char>(s[i + k]);
      ok = (cont & 0xC0) == 0x80;
      c = (c << 6) | (cont & 0x3F);
    }
    out.push_back(ok ? c : U'\uFFFD');
    i += ok ? len : 1;
  }
  return out;
}

constexpr uint32_t kMax32 = 0xFFFFFFFF;
constexpr uint16_t kUtf8Names = 0x0800;  // general purpose flag bit 11
constexpr uint16_t kDate1980 = (1 << 5) | 1;  // 1980-01-01 00:00: fixed, so a seed gives the same bytes

}  // namespace

std::string NpyHeader(const std::string& descr, uint64_t n) {
  std::string dict = fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': ({},), }}", descr, n);
  // magic (6) + version (2) + length (2) + dict + padding + '\n', a multiple of 64 bytes.
  const size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict.push_back('\n');
  std::string header("\x93NUMPY\x01\x00", 8);
  PutLe(header, dict.size(), 2);
  return header + dict;
}

void NpzWriter::Put(const void* data, uint64_t size) {
  out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  written_ += size;
}

void NpzWriter::Add(const std::string& name, const std::string& header, const void* data, uint64_t data_size) {
  Entry e{name + ".npy", 0, header.size() + data_size, written_};
  uLong crc = crc32_z(0L, reinterpret_cast<const Bytef*>(header.data()), header.size());
  e.crc = static_cast<uint32_t>(crc32_z(crc, static_cast<const Bytef*>(data), data_size));
  const bool zip64 = e.size >= kMax32;
  std::string local;
  PutLe(local, 0x04034b50, 4);
  PutLe(local, zip64 ? 45 : 20, 2);  // version needed: 4.5 for zip64, else 2.0
  PutLe(local, kUtf8Names, 2);
  PutLe(local, 0, 2);  // stored
  PutLe(local, 0, 2);  // time
  PutLe(local, kDate1980, 2);
  PutLe(local, e.crc, 4);
  PutLe(local, zip64 ? kMax32 : e.size, 4);  // compressed size
  PutLe(local, zip64 ? kMax32 : e.size, 4);  // uncompressed size
  PutLe(local, e.name.size(), 2);
  PutLe(local, zip64 ? 20 : 0, 2);  // extra field length
  local += e.name;
  if (zip64) {
    PutLe(local, 0x0001, 2);
    PutLe(local, 16, 2);
    PutLe(local, e.size, 8);
    PutLe(local, e.size, 8);
  }
  Put(local.data(), local.size());
  Put(header.data(), header.size());
  Put(data, data_size);
  entries_.push_back(std::move(e));
}

void NpzWriter::AddDoubles(const std::string& name, const double* values, uint64_t n) {
  static_assert(sizeof(double) == 8, "float64");
  Add(name, NpyHeader(LittleEndian() ? "<f8" : ">f8", n), values, n * sizeof(double));
}

void NpzWriter::AddStrings(const std::string& name, const std::vector<std::string>& utf8) {
  std::vector<std::u32string> decoded;
  size_t width = 1;  // numpy's '<U0' is not a valid itemsize for readers of old numpy
  for (const auto& s : utf8) {
    decoded.push_back(DecodeUtf8(s));
    width = std::max(width, decoded.back().size());
  }
  std::vector<char32_t> data(width * decoded.size(), U'\0');
  for (size_t i = 0; i < decoded.size(); ++i) std::copy(decoded[i].begin(), decoded[i].end(), data.begin() + i * width);
  Add(name, NpyHeader(fmt::format("{}U{}", LittleEndian() ? '<' : '>', width), decoded.size()), data.data(),
      data.size() * sizeof(char32_t));
}

void NpzWriter::Finish() {
  const uint64_t cd_offset = written_;
  for (const Entry& e : entries_) {
    const bool big_size = e.size >= kMax32, big_offset = e.offset >= kMax32;
    std::string extra;
    if (big_size || big_offset) {
      std::string fields;
      if (big_size) {
        PutLe(fields, e.size, 8);  // uncompressed
        PutLe(fields, e.size, 8);  // compressed
      }
      if (big_offset) PutLe(fields, e.offset, 8);
      PutLe(extra, 0x0001, 2);
      PutLe(extra, fields.size(), 2);
      extra += fields;
    }
    std::string c;
    PutLe(c, 0x02014b50, 4);
    PutLe(c, 45, 2);                          // made by: 4.5
    PutLe(c, extra.empty() ? 20 : 45, 2);     // version needed
    PutLe(c, kUtf8Names, 2);
    PutLe(c, 0, 2);  // stored
    PutLe(c, 0, 2);  // time
    PutLe(c, kDate1980, 2);
    PutLe(c, e.crc, 4);
    PutLe(c, big_size ? kMax32 : e.size, 4);
    PutLe(c, big_size ? kMax32 : e.size, 4);
    PutLe(c, e.name.size(), 2);
    PutLe(c, extra.size(), 2);
    PutLe(c, 0, 2);  // comment length
    PutLe(c, 0, 2);  // disk
    PutLe(c, 0, 2);  // internal attributes
    PutLe(c, 0, 4);  // external attributes
    PutLe(c, big_offset ? kMax32 : e.offset, 4);
    c += e.name;
    c += extra;
    Put(c.data(), c.size());
  }
  const uint64_t cd_size = written_ - cd_offset, count = entries_.size();
  std::string end;
  if (count >= 0xFFFF || cd_size >= kMax32 || cd_offset >= kMax32) {
    const uint64_t zip64_end = written_;
    PutLe(end, 0x06064b50, 4);
    PutLe(end, 44, 8);  // size of the rest of this record
    PutLe(end, 45, 2);
    PutLe(end, 45, 2);
    PutLe(end, 0, 4);
    PutLe(end, 0, 4);
    PutLe(end, count, 8);
    PutLe(end, count, 8);
    PutLe(end, cd_size, 8);
    PutLe(end, cd_offset, 8);
    PutLe(end, 0x07064b50, 4);  // locator
    PutLe(end, 0, 4);
    PutLe(end, zip64_end, 8);
    PutLe(end, 1, 4);
  }
  PutLe(end, 0x06054b50, 4);
  PutLe(end, 0, 2);
  PutLe(end, 0, 2);
  PutLe(end, std::min<uint64_t>(count, 0xFFFF), 2);
  PutLe(end, std::min<uint64_t>(count, 0xFFFF), 2);
  PutLe(end, std::min<uint64_t>(cd_size, kMax32), 4);
  PutLe(end, std::min<uint64_t>(cd_offset, kMax32), 4);
  PutLe(end, 0, 2);  // comment length
  Put(end.data(), end.size());
}

void WriteTraceNpz(const Trace& trace, std::ostream& out) {
  std::vector<std::string> ids;
  std::set<std::string> seen;
  for (const Run& r : trace.runs) {
    if (!seen.insert(r.id).second) throw InputError(fmt::format("run id '{}' appears twice: .npz keys must be unique", r.id));
    ids.push_back(r.id);
  }
  NpzWriter npz(out);
  npz.AddStrings("runs", ids);
  npz.AddStrings("comments", trace.comments);
  for (const Run& r : trace.runs) {
    npz.AddDoubles(r.id + "/t_s", r.t_s.data(), r.t_s.size());
    for (size_t c = 0; c < r.names.size(); ++c) npz.AddDoubles(r.id + "/" + r.names[c], r.columns[c].data(), r.columns[c].size());
  }
  npz.Finish();
}

}  // namespace rlg::io
