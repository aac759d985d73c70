// FigurePool (report/figure_pool.hpp) draws figures with several gnuplot processes at once.
// Truth: the files on disk and what gnuplot itself wrote into them, not the code under test: each
// SVG carries its own figure's key title (gnuplot writes it as text), each PNG is whole (PNG
// specification, section 11.2.5: it ends with the IEND chunk) and has the size the script set
// (the IHDR chunk's width and height, section 11.2.2), and gnuplot's own error message for a
// broken script comes back naming that script's file.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "file_test_support.hpp"
#include "model/environment_error.hpp"
#include "report/figure_pool.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

GnuplotFigure Series(int k) {
  const std::string name = "series_" + std::to_string(k);
  std::string data;
  for (int i = 0; i <= 50; ++i) data += std::to_string(i) + " " + std::to_string(i * k) + "\n";
  return {name, "Series " + std::to_string(k), "y = k x", data,
          "plot '" + name + ".dat' using 1:2 with linespoints title 'series number " + std::to_string(k) + "'"};
}

std::uint32_t BigEndian32(const std::string& s, std::size_t at) {
  return (std::uint32_t(std::uint8_t(s[at])) << 24) | (std::uint32_t(std::uint8_t(s[at + 1])) << 16) |
         (std::uint32_t(std::uint8_t(s[at + 2])) << 8) | std::uint32_t(std::uint8_t(s[at + 3]));
}

// Whole as gnuplot wrote it: the key title in the SVG's text, a PNG that ends with IEND and whose
// IHDR (bytes 16..23) says 1350 x 900, the size gnuplot_figure.cpp's script asks for.
void ExpectWhole(const fs::path& dir, int k) {
  const std::string name = "series_" + std::to_string(k);
  const std::string svg = ReadBytes(dir / (name + ".svg"));
  EXPECT_NE(svg.find("series number " + std::to_string(k) + "<"), std::string::npos) << name;
  EXPECT_NE(svg.rfind("</svg>"), std::string::npos) << name;
  const std::string png = ReadBytes(dir / (name + ".png"));
  ASSERT_GT(png.size(), 33u) << name;
  EXPECT_EQ(png.substr(12, 4), "IHDR") << name;
  EXPECT_EQ(BigEndian32(png, 16), 1350u) << name;
  EXPECT_EQ(BigEndian32(png, 20), 900u) << name;
  EXPECT_EQ(png.substr(png.size() - 8), std::string("IEND\xae\x42\x60\x82", 8)) << name;
  EXPECT_EQ(ReadBytes(dir / (name + ".dat")), Series(k).data) << name;
}

// Nothing of the private render folders is left behind.
void ExpectNoRenderFolders(const fs::path& dir) {
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".render-"), std::string::npos) << e.path();
}

TEST(FigurePool, FiguresDrawnAtOnceAreAllWholeAndTheirOwn) {
  const fs::path dir = FreshFolder("figure-pool");
  constexpr int kFigures = 12;
  {
    FigurePool pool(4);
    for (int k = 1; k <= kFigures; ++k) pool.Render(Series(k), dir.string());
    pool.Wait();
  }
  for (int k = 1; k <= kFigures; ++k) ExpectWhole(dir, k);
  ExpectNoRenderFolders(dir);

  // Drawn again by another pool with nothing changed: reused (RenderFigure's rule), so the
  // images keep the older time they were given here.
  const auto old = fs::last_write_time(dir / "series_1.png") - std::chrono::hours(1);
  for (int k = 1; k <= kFigures; ++k) {
    const std::string name = "series_" + std::to_string(k);
    for (const char* ext : {".dat", ".gp"}) fs::last_write_time(dir / (name + ext), old - std::chrono::hours(1));
    for (const char* ext : {".svg", ".png"}) fs::last_write_time(dir / (name + ext), old);
  }
  FigurePool again(3);
  for (int k = 1; k <= kFigures; ++k) again.Render(Series(k), dir.string());
  again.Wait();
  for (int k = 1; k <= kFigures; ++k) EXPECT_EQ(fs::last_write_time(dir / ("series_" + std::to_string(k) + ".png")), old);
  fs::remove_all(dir);
}

TEST(FigurePool, AFailingScriptIsNamedWithItsFileAndTheOthersAreWritten) {
  const fs::path dir = FreshFolder("figure-pool-failing");
  FigurePool pool(3);
  for (int k = 1; k <= 6; ++k) {
    if (k == 4) {
      // gnuplot's own complaint: an unknown style in the plot command of broken.gp.
      pool.Render({"broken", "Broken", "", "0 0\n1 1\n", "plot 'broken.dat' using 1:2 with no_such_style"},
                  dir.string());
    }
    pool.Render(Series(k), dir.string());
  }
  try {
    pool.Wait();
    FAIL() << "a broken script was accepted";
  } catch (const EnvironmentError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find((dir / "broken.gp").string()), std::string::npos) << message;
    EXPECT_NE(message.find("gnuplot failed"), std::string::npos) << message;
    EXPECT_NE(message.find("line"), std::string::npos) << message;  // gnuplot's "broken.gp" line N:
    EXPECT_EQ(message.find("series_"), std::string::npos) << message;
  }
  for (int k = 1; k <= 6; ++k) ExpectWhole(dir, k);
  EXPECT_FALSE(fs::exists(dir / "broken.svg"));
  EXPECT_FALSE(fs::exists(dir / "broken.png"));
  ExpectNoRenderFolders(dir);
  pool.Wait();  // the failure was reported once
  fs::remove_all(dir);
}

// A machine without gnuplot: every figure fails for the same reason, which is the machine's,
// not a figure's. The truth is the rule of figure_pool.hpp: the reason is given once, with the
// number of figures it stopped (it used to be repeated for each figure). PATH is pointed at an
// empty folder, so posix_spawnp finds no gnuplot.
TEST(FigurePool, AMissingGnuplotIsReportedOnceWithTheNumberOfFigures) {
  const fs::path dir = FreshFolder("figure-pool-no-gnuplot");
  const fs::path empty = FreshFolder("figure-pool-empty-path");
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path ? old_path : "";
  ::setenv("PATH", empty.c_str(), 1);
  std::string message;
  {
    FigurePool pool(2);
    for (int k = 1; k <= 5; ++k) pool.Render(Series(k), dir.string());
    try {
      pool.Wait();
    } catch (const EnvironmentError& e) {
      message = e.what();
    }
  }
  ::setenv("PATH", saved.c_str(), 1);
  const std::string reason = "gnuplot not found (install Debian's gnuplot-nox)";
  ASSERT_NE(message.find(reason), std::string::npos) << message;
  EXPECT_EQ(message.find(reason), message.rfind(reason)) << message;
  EXPECT_NE(message.find("5 figures failed"), std::string::npos) << message;
  EXPECT_NE(message.find("(5 figures)"), std::string::npos) << message;
  for (int k = 1; k <= 5; ++k) EXPECT_FALSE(fs::exists(dir / ("series_" + std::to_string(k) + ".svg")));
  ExpectNoRenderFolders(dir);
  fs::remove_all(dir);
  fs::remove_all(empty);
}

TEST(FigurePool, AFigureSubmittedTwiceIsDrawnOnceAndDifferentContentIsRefused) {
  const fs::path dir = FreshFolder("figure-pool-twice");
  FigurePool pool(2);
  pool.Render(Series(1), dir.string());
  pool.Render(Series(1), dir.string());
  GnuplotFigure other = Series(2);
  other.name = "series_1";
  EXPECT_THROW(pool.Render(other, dir.string()), std::logic_error);
  pool.Wait();
  ExpectWhole(dir, 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
