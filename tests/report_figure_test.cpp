// RenderFigure (report/gnuplot_figure.hpp) draws a figure again only when something changed.
// Truth: the files themselves (bytes, modification times) and the PNG specification's ending
// (section 11.2.5: the IEND chunk), not the code under test: gnuplot runs or not, and a figure
// is reused only when its data, its script and whole images newer than both are on disk.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "file_test_support.hpp"
#include "report/gnuplot_figure.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

GnuplotFigure Line(const std::string& data) {
  return {"line", "A line", "y against x", data, "plot 'line.dat' using 1:2 with lines title 'y'"};
}

TEST(RenderFigureReuse, AnUnchangedFigureIsNotDrawnAgainAndAChangedOrBrokenOneIs) {
  const fs::path dir = FreshFolder("figure-reuse");
  RenderFigure(Line("0 0\n1 1\n"), dir.string());
  const fs::path png = dir / "line.png", svg = dir / "line.svg";
  const std::string first_png = ReadBytes(png);
  ASSERT_GT(first_png.size(), 100u);

  // Marked old: had it been drawn again, the new images would carry a newer time.
  const auto old = fs::last_write_time(png) - std::chrono::hours(1);
  fs::last_write_time(dir / "line.dat", old - std::chrono::hours(1));
  fs::last_write_time(dir / "line.gp", old - std::chrono::hours(1));
  fs::last_write_time(png, old);
  fs::last_write_time(svg, old);
  RenderFigure(Line("0 0\n1 1\n"), dir.string());
  EXPECT_EQ(fs::last_write_time(png), old);
  EXPECT_EQ(fs::last_write_time(svg), old);

  // Other numbers: drawn again.
  RenderFigure(Line("0 0\n1 2\n"), dir.string());
  EXPECT_GT(fs::last_write_time(png), old);
  EXPECT_EQ(ReadBytes(dir / "line.dat"), "0 0\n1 2\n");

  // A truncated image (a full disk in an earlier run): drawn again, whole.
  const std::string whole = ReadBytes(png);
  { std::ofstream(png, std::ios::binary | std::ios::trunc) << whole.substr(0, whole.size() / 2); }
  RenderFigure(Line("0 0\n1 2\n"), dir.string());
  const std::string redrawn = ReadBytes(png);
  ASSERT_GE(redrawn.size(), 12u);
  EXPECT_EQ(redrawn.substr(redrawn.size() - 8), std::string("IEND\xae\x42\x60\x82", 8));

  // Images older than the script (a run stopped after writing it): drawn again.
  fs::last_write_time(png, old);
  fs::last_write_time(dir / "line.gp", old + std::chrono::minutes(1));
  RenderFigure(Line("0 0\n1 2\n"), dir.string());
  EXPECT_GT(fs::last_write_time(png), old + std::chrono::minutes(1));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uphill::testing
