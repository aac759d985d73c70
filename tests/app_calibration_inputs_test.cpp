// The calibration inputs (src/app/calibration_inputs.hpp): POINTS.csv in any length unit, and the
// printable chessboard target. Truth: the values written into the file here; the target's size
// from its geometry ((cols + 1 + 2) squares across); OpenCV's own detector
// (cv::findChessboardCornersSB) finding every inner corner of the PNG.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <unistd.h>

#include "app/calibration_inputs.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

namespace fs = std::filesystem;

std::string WriteFile(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / ("uphill_app_calibration_" + std::to_string(::getpid()) + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(ReadScenePoints, UnitsInTheHeaderOrInTheCellsGiveMetres) {
  const std::string path = WriteFile("points.csv",
                                     "name,u_px,v,x_mm,y,z_cm,note\n"
                                     "crossbar,640.5,360,350,50mm,0,left end\n"
                                     ",10,20,-2.5,1in,1.5,\n");
  const std::vector<ScenePoint> points = ReadScenePoints(path);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].label, path + ", row 2 (crossbar)");
  EXPECT_EQ(points[1].label, path + ", row 3");
  EXPECT_EQ(points[0].pixel.x(), 640.5);
  EXPECT_EQ(points[0].pixel.y(), 360.0);
  EXPECT_DOUBLE_EQ(points[0].position.x(), 0.350);
  EXPECT_DOUBLE_EQ(points[0].position.y(), 0.050);
  EXPECT_EQ(points[0].position.z(), 0.0);
  EXPECT_DOUBLE_EQ(points[1].position.x(), -0.0025);
  EXPECT_DOUBLE_EQ(points[1].position.y(), 0.0254);
  EXPECT_DOUBLE_EQ(points[1].position.z(), 0.015);
  fs::remove(path);
}

TEST(ReadScenePoints, BadColumnsAndCellsNameTheFileRowAndColumn) {
  const auto error = [](const std::string& text) {
    const std::string path = WriteFile("bad.csv", text);
    std::string what = "no error";
    try {
      ReadScenePoints(path);
    } catch (const InputError& e) {
      what = e.what();
    }
    fs::remove(path);
    return std::regex_replace(what, std::regex("^[^,:]*bad\\.csv"), "bad.csv");
  };
  EXPECT_EQ(error("u,v,x_mm,y_mm,w_mm\n1,2,3,4,5\n").rfind("bad.csv, row 1, column w_mm: unknown column", 0), 0u);
  EXPECT_EQ(error("u,v,x_mm,y_mm\n1,2,3,4\n"),
            "bad.csv, row 1: the header must have the columns u, v, x, y, z (e.g. u,v,x_mm,y_mm,z_mm)");
  EXPECT_EQ(error("u,v,x_mm,y_mm,z_mm\n1,2,3,four,5\n").rfind("bad.csv, row 2, column y_mm: ", 0), 0u);
}

TEST(ChessboardTarget, SvgHasTheExactSizeAndEveryOtherSquareBlack) {
  const ChessboardTarget target{9, 6, 0.02};
  const std::string svg = ChessboardTargetSvg(target);
  EXPECT_NE(svg.find("width=\"240mm\" height=\"180mm\" viewBox=\"0 0 240 180\""), std::string::npos);
  std::size_t black = 0;
  for (std::size_t at = svg.find("fill=\"black\""); at != std::string::npos; at = svg.find("fill=\"black\"", at + 1))
    ++black;
  EXPECT_EQ(black, 35u);  // 10 × 7 squares, half of them (rounded up) black
}

TEST(ChessboardTarget, PngIsDetectedByOpenCvAtThePrintersResolution) {
  const ChessboardTarget target{9, 6, 0.02};
  const TargetPng png = ChessboardTargetPng(target, 127);  // 20 mm at 127 dpi = 100 px
  EXPECT_EQ(png.pixels_per_square, 100);
  EXPECT_EQ(png.width, 1200);
  EXPECT_EQ(png.height, 900);
  const std::vector<uchar> bytes(png.bytes.begin(), png.bytes.end());
  const cv::Mat image = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(image.cols, 1200);
  std::vector<cv::Point2f> corners;
  EXPECT_TRUE(cv::findChessboardCornersSB(image, cv::Size(9, 6), corners));
  EXPECT_EQ(corners.size(), 54u);
  EXPECT_THROW(ChessboardTargetPng(target, 1e300), InputError);
}

}  // namespace
}  // namespace uphill::testing
