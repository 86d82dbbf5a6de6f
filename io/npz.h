#pragma once
/// numpy's .npz: a trace as binary arrays that `numpy.load` reads without any code of ours, for
/// populations too large for CSV (writing a 24 h run takes 0.9 ms against the CSV's 55 ms,
/// before the disk; README "Speed"). The values are the simulator's doubles, unrounded (the CSV
/// rounds to 4 or 6 decimals).
///
/// The file is a zip archive, every member stored (not compressed), of .npy files (numpy's
/// format version 1.0: the 6 bytes "\x93NUMPY", version bytes 1 and 0, a little-endian uint16
/// header length, then the header, a Python dict literal
///   {'descr': '<f8', 'fortran_order': False, 'shape': (n,), }
/// padded with spaces and ended by '\n' so that the data starts at a multiple of 64 bytes,
/// then the n values). Members of a trace (WriteTraceNpz), by `np.load(path)` key:
///   runs              1-D str array: the run ids, in order
///   comments          1-D str array: the header comments of the CSV (command line, gyro)
///   <run>/t_s         float64, s
///   <run>/<column>    float64, one per data column (T_amb, T1.., bias_dph, P_<source>_W), units
///                     as in the CSV (docs/data-format.md)
/// Keys hold the run id as written, so split a key at its last '/' (a column name has none).
/// Strings are numpy's '<U' (UTF-32) arrays, readable with allow_pickle=False; names are UTF-8
/// with the zip's UTF-8 flag set. Zip64 records are added when a member, an offset or the member
/// count passes the 32/16-bit fields, so there is no size limit. Values are written in the
/// machine's byte order, and the descr says which ('<f8' on x86-64).

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "sim/trace.h"

namespace rlg::io {

/// The .npy header (magic, version, length, dict, padding) of a 1-D array of `n` elements of
/// numpy type `descr` (e.g. "<f8", "<U12"); the data follows it directly.
std::string NpyHeader(const std::string& descr, uint64_t n);

/// Writes an .npz to a stream, one array at a time (nothing is kept but the directory), then the
/// zip's central directory on Finish(). The stream must be binary and start empty; an array's
/// name is its np.load key (".npy" is appended).
class NpzWriter {
 public:
  explicit NpzWriter(std::ostream& out) : out_(out) {}
  void AddDoubles(const std::string& name, const double* values, uint64_t n);
  void AddStrings(const std::string& name, const std::vector<std::string>& utf8);
  /// Writes the central directory; the archive is incomplete without it.
  void Finish();

 private:
  struct Entry {
    std::string name;
    uint32_t crc;
    uint64_t size;
    uint64_t offset;
  };
  void Add(const std::string& name, const std::string& header, const void* data, uint64_t data_size);
  void Put(const void* data, uint64_t size);
  std::ostream& out_;
  uint64_t written_ = 0;
  std::vector<Entry> entries_;
};

/// Writes `trace` as .npz (members above). Run ids must be unique.
void WriteTraceNpz(const sim::Trace& trace, std::ostream& out);

}  // namespace rlg::io
