#pragma once
/// Streaming compensation: tidy-CSV rows in, the same rows with the compensated column added
/// out, one row at a time, as a gyro computer runs it (`rlgtherm compensate --stream`). Every
/// row goes through one Compensator (compensator.h; any model: model_compensator.h), reset at the first row of each run, the
/// loop batch compensation (CompensateRun) runs too; rows are written by the CsvRowWriter that
/// WriteTraceCsv uses. So the output equals batch compensation written with WriteTraceCsv,
/// byte for byte.

#include <functional>
#include <iosfwd>
#include <string>

#include "io/csv.h"
#include "model/compensation_model.h"
#include "model/guo2006.h"

namespace rlg::compensation {

struct StreamOptions {
  /// The rate column compensated (°/h), written to CompensatedColumnName(bias_column).
  std::string bias_column = "bias_dph";
  /// The data as the user named it, in the refusal of data without a column the coefficients
  /// or bias_column need.
  std::string data_name;
  /// Called after each row is written and flushed (the CLI checks standard output there, so
  /// that it stops at the first row that cannot be written). May throw.
  std::function<void()> after_row;
};

/// What a CsvRowReader for CompensateStream must keep: bias_column beside the tidy CSV's
/// columns when it is not bias_dph, bias_dph required when it is.
io::CsvReadOptions StreamReadOptions(const std::string& bias_column);

/// Compensates every row of `reader` (made with StreamReadOptions) to `out`: the reader's comment
/// lines and the header run,t_s,<its columns>,<compensated column>, then one row per input row,
/// flushed as it is written. InputError, before anything is written, for input without data
/// rows (the batch reader's message, naming the reader's source) and for data without the
/// coefficients' pair or bias_column; the reader's refusals of a row as it comes (rows before
/// it are out by then). Returns the number of rows written.
size_t CompensateStream(const model::Guo2006Coefficients& coefficients, io::CsvRowReader& reader, std::ostream& out,
                        const StreamOptions& options);
/// The same for any model of the family (model_compensator.h): Eq. (2) exactly as above; a
/// polynomial model needs its channels (the refusal names them) and bias_column.
size_t CompensateStream(const model::FittedModel& model, io::CsvRowReader& reader, std::ostream& out,
                        const StreamOptions& options);

}  // namespace rlg::compensation
