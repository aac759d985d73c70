// Output of `uphill convert`: a readable table (lab units, each column naming its unit), CSV
// (the same columns) or JSON (SI, io::ToJson). Failed rows of a batch appear in every format,
// with their error, so the output lines up with the input rows.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "io/conversion.hpp"

namespace uphill::cli {

// One input configuration's outcome: a result, or the one-line error it got.
struct ConvertedRow {
  int row = 0;  // spreadsheet row of a batch, 0 for a configuration from flags
  std::optional<io::ConversionResult> result;
  std::string error;
};

enum class OutputFormat { kTable, kCsv, kJson };

void PrintConversion(std::ostream& out, const std::vector<ConvertedRow>& rows, OutputFormat format,
                     bool batch, const std::string& length_unit);

}  // namespace uphill::cli
