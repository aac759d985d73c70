// One experiment folder, two readers on one file reader (src/io/experiment_folder.hpp): the
// analysis' LoadExperiment (rows as configurations) and the page's LoadStateFromFiles (rows as
// typed) must see the same trials and the same numbers. Truth: the sample folders in data/ and a
// folder written here in other units; the two readers agree with each other and with the file.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "io/experiment.hpp"
#include "io/experiment_folder.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "server/experiment_state.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

// Rows of both readers side by side: same trials in the same order, and every Y the page shows
// (text in the state's unit) is the analysis' Y (metres) to the printed digits.
void ExpectSameRows(const std::string& dir) {
  const Experiment experiment = LoadExperiment(dir);
  const ExperimentState state = LoadStateFromFiles(dir);
  ASSERT_EQ(state.rows.size(), experiment.rows.size());
  for (std::size_t i = 0; i < state.rows.size(); ++i) {
    SCOPED_TRACE(experiment.rows[i].trial);
    ASSERT_TRUE(experiment.rows[i].error.empty()) << experiment.rows[i].error;
    EXPECT_EQ(state.rows[i].trial, experiment.rows[i].trial);
    EXPECT_EQ(state.rows[i].series, experiment.rows[i].series);
    EXPECT_EQ(state.rows[i].note, experiment.rows[i].note);
    const double y = ToUnit(experiment.rows[i].Y.value, Dimension::kLength, state.unit);
    EXPECT_NEAR(std::strtod(state.rows[i].Value("Y").c_str(), nullptr), y, 1e-9 * y);
  }
  EXPECT_EQ(state.metadata.at("format"), kExperimentFormat);
  EXPECT_EQ(state.metadata.at("title"), experiment.title);
}

TEST(ExperimentFolder, BothReadersSeeTheSampleSeriesAlike) {
  for (const char* series : {"series1-fixed-D", "series2-fixed-L"})
    ExpectSameRows(std::string(UPHILL_SOURCE_DIR) + "/data/" + series);
}

TEST(ExperimentFolder, OtherUnitsAreReExpressedInTheYColumnsUnit) {
  const fs::path dir = fs::temp_directory_path() / ("uphill_folder_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / kExperimentJsonFile)
      << R"({"format": "uphill-experiment/1", "title": "units", "body": {"type": "sphere", "R": "12.7 mm"},
             "apparatus": {"H": "300 mm"}})";
  std::ofstream(dir / kMeasurementsCsvFile) << "trial,L_m,D,Y_cm\nt1,1.165,100 mm,38.5\nt2,1.2,4 in,40\n";
  ExpectSameRows(dir.string());
  const ExperimentState state = LoadStateFromFiles(dir.string());
  EXPECT_EQ(state.unit, "cm");
  EXPECT_EQ(state.rows[0].Value("L"), "116.5");
  EXPECT_EQ(state.rows[1].Value("D"), "10.16");
  fs::remove_all(dir);
}

TEST(ExperimentFolder, AFolderWithoutMeasurementsIsAnEmptyStateButNoExperiment) {
  const fs::path dir = fs::temp_directory_path() / ("uphill_folder_empty_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / kExperimentJsonFile)
      << R"({"format": "uphill-experiment/1", "body": {"type": "sphere", "R": "12.7 mm"}})";
  EXPECT_TRUE(LoadStateFromFiles(dir.string()).rows.empty());
  try {
    LoadExperiment(dir.string());
    ADD_FAILURE() << "loaded a folder without measurements.csv";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / kMeasurementsCsvFile).string() + ": cannot be opened for reading");
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
