// Fuzz target: the batch path of `uphill convert --batch` itself (ConvertBatch of
// src/app/convert_batch.hpp, reading the CSV record by record, without command-line defaults):
// the column check, ParseConfiguration per row (or the numeric short path), Convert with
// first-order uncertainties only (Monte Carlo trials = 0) and the rest band, and the JSON of
// every row converted; then a point halfway along each path, as --at-x would ask for. Only
// uphill::InputError may escape; anything else (a crash, a sanitizer report, another exception)
// is a bug.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>

#include "app/convert_batch.hpp"
#include "model/input_error.hpp"

namespace {

using namespace uphill;

// No command-line defaults: every field comes from the table.
FieldSource NoDefaults() {
  FieldSource s;
  s.lookup = [](const std::string&) -> std::optional<FieldSource::Field> { return std::nullopt; };
  s.context = [](const std::string& name) { return name; };
  return s;
}

void Run(const std::string& text) {
  std::istringstream in(text);
  ConversionOptions options;
  options.mu = 0.01;
  options.propagation.trials = 0;  // first order only: Monte Carlo is the model's, not the reader's
  int rows = 0;
  ConvertBatch(in, "fuzz.csv", NoDefaults(), options, [](const BatchHeader&) {}, [&](const ConvertedRow& row) {
    if (++rows > 32 || !row.result) return;  // a bad row: reported by convert, the others go on
    (void)ToJson(*row.result).dump();
    ConversionOptions at_x;
    at_x.propagation.trials = 0;
    at_x.at_x = {0.5 * (row.result->scene.x_low() + row.result->scene.x_max())};
    try {
      (void)ToJson(Convert(row.result->configuration, at_x)).dump();
    } catch (const InputError&) {
      // A midpoint off the path of a degenerate scene: refused like any --at-x.
    }
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    Run(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const InputError&) {
    // The documented refusal of a whole file.
  }
  return 0;
}
