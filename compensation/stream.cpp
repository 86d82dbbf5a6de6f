#include "compensation/stream.h"

#include <algorithm>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <vector>

#include "compensation/compensator.h"
#include "compensation/model_compensator.h"
#include "sim/errors.h"

namespace rlg::compensation {

io::CsvReadOptions StreamReadOptions(const std::string& bias_column) {
  io::CsvReadOptions options;
  if (bias_column != "bias_dph") options.keep_columns = {bias_column};
  options.require_bias = bias_column == "bias_dph";
  return options;
}

namespace {

/// The streaming loop of both compensators: the columns of `channels` and the bias column found
/// (a missing one refused, `read` saying what the coefficients read), the header written, then
/// each row with its compensated bias, flushed as it comes. `reset()` starts a run;
/// `update(t_s, T, bias_dph)` takes the channels' values in the order of `channels`.
template <typename Reset, typename Update>
size_t StreamRows(io::CsvRowReader& reader, io::CsvRow& row, std::ostream& out, const StreamOptions& options,
                  const std::vector<std::string>& channels, const std::string& read, Reset reset, Update update) {
  const auto& names = reader.names();
  auto index = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      throw InputError(fmt::format("{}: no column '{}' (the coefficients use {})", options.data_name, name, read));
    }
    return static_cast<size_t>(it - names.begin());
  };
  std::vector<size_t> channel_index;
  for (const auto& ch : channels) channel_index.push_back(index(ch));
  const size_t b = index(options.bias_column);
  std::vector<std::string> out_names = names;
  out_names.push_back(CompensatedColumnName(options.bias_column));
  io::CsvRowWriter writer(out, out_names, reader.comments());
  std::vector<double> values(out_names.size()), T(channel_index.size());
  size_t rows = 0;
  do {
    if (row.new_run) reset();
    std::copy(row.values.begin(), row.values.end(), values.begin());
    for (size_t c = 0; c < channel_index.size(); ++c) T[c] = row.values[channel_index[c]];
    values.back() = update(row.t_s, T.data(), row.values[b]);
    writer.Write(row.run, row.t_s, values.data());
    writer.Flush();  // a gyro computer's consumer wants each sample as it comes
    ++rows;
    if (options.after_row) options.after_row();
  } while (reader.Next(row));
  return rows;
}

}  // namespace

size_t CompensateStream(const model::Guo2006Coefficients& coefficients, io::CsvRowReader& reader, std::ostream& out,
                        const StreamOptions& options) {
  io::CsvRow row;
  // A file without data rows is refused as in batch mode (same check first, same message),
  // before anything goes out.
  if (!reader.Next(row)) io::ThrowNoDataRows(reader.path(), reader.line());
  Compensator comp(coefficients);
  const std::vector<std::string> pair(coefficients.pair.begin(), coefficients.pair.end());
  return StreamRows(
      reader, row, out, options, pair, fmt::format("pair {},{}", pair[0], pair[1]), [&] { comp.Reset(); },
      [&](double t_s, const double* T, double bias_dph) { return comp.Update(t_s, T[0], T[1], bias_dph); });
}

size_t CompensateStream(const model::FittedModel& model, io::CsvRowReader& reader, std::ostream& out,
                        const StreamOptions& options) {
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&model)) return CompensateStream(*c, reader, out, options);
  io::CsvRow row;
  if (!reader.Next(row)) io::ThrowNoDataRows(reader.path(), reader.line());
  ModelCompensator comp(model);
  const std::vector<std::string>& channels = comp.channels();
  return StreamRows(
      reader, row, out, options, channels,
      fmt::format("channel{} {}", channels.size() == 1 ? "" : "s", fmt::join(channels, ",")), [&] { comp.Reset(); },
      [&](double t_s, const double* T, double bias_dph) { return comp.Update(t_s, T, bias_dph); });
}

}  // namespace rlg::compensation
