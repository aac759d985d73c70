// `uphill paper-figures`: every figure of the seed paper is written with its script and data,
// and the gallery opens offline.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_test_support.hpp"

namespace uphill::testing {
namespace {

TEST(PaperFiguresCli, WritesEveryFigureAndASelfContainedGallery) {
  namespace fs = std::filesystem;
  const fs::path out = fs::temp_directory_path() / "uphill_paper_figures_test";
  fs::remove_all(out);
  const auto r = testing::RunUphill("paper-figures -o " + out.string() + " --data " UPHILL_SOURCE_DIR "/data");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* stem : {"fig_potential", "fig_x_vs_phi", "fig_x_vs_theta", "fig_sphere_xz_t", "fig_sphere_speed_x",
                           "fig_sphere_speed_t", "series1-fixed-D/fit_y_vs_x", "series2-fixed-L/fit_y_vs_x"})
    for (const char* ext : {".svg", ".png", ".gp", ".dat"})
      EXPECT_TRUE(fs::exists(out / (std::string(stem) + ext))) << stem << ext;
  std::stringstream html;
  html << std::ifstream(out / "index.html").rdbuf();
  std::stringstream script;
  script << std::ifstream(out / "fig_sphere_xz_t.gp").rdbuf();
  EXPECT_NE(script.str().find("paper eq. 8"), std::string::npos);  // the paper's curve, labelled
  EXPECT_EQ(html.str().find("http"), std::string::npos);
  size_t images = 0;
  for (size_t at = 0; (at = html.str().find("data:image/svg+xml;base64,", at)) != std::string::npos; ++at) ++images;
  EXPECT_EQ(images, 10u);  // 6 model figures, 2 × 2 experiment figures
  fs::remove_all(out);
}

}  // namespace
}  // namespace uphill::testing
