// The camera's exposure and sensor for the physically based footage (footage_clip.hpp): when each
// row sees the scene, how the light varies in time, and how light becomes an 8-bit sRGB pixel.
//
// Time (ShutterTiming): frame f's row r (raw pixel row, v = r) is exposed over
//   [t_row − E/2, t_row + E/2],   t_row = t0 + f/fps + r·readout/H,
// E the exposure time (shutter angle/360° · 1/fps), H the image height, readout the rolling
// shutter's readout time (0: a global shutter; phones read the rows over 20–30 ms). A frame's
// timestamp f/fps (+ t0) is thus the mid-exposure of its first row, and of every row for a global
// shutter.
//
// Light (LightModel): the scene's radiance is scaled by g(t) = (1 + m·cos(2π·f_flicker·t + φ)) ·
// (1 + d·sin(2π·t/T_drift)): mains flicker of a lamp (m the modulation depth, f_flicker = 100 Hz on
// 50 Hz mains) and a slow automatic-exposure drift (d, T_drift). A row records the average of g
// over its exposure; with a rolling shutter the flicker shows as horizontal bands. The flicker
// integral is in closed form; the drift, slow against any exposure, by the midpoint rule (relative
// error ≤ (π·E/T_drift)²·d/6 < 1e-4 for E ≤ 1/30 s, T_drift ≥ 1 s).
//
// Sensor (SensorModel): the linear signal S (1 = the white level) becomes electrons S·full_well,
// with shot noise (variance = the electrons) and read noise (read_noise electrons rms), Gaussian
// (the Poisson law is Gaussian to < 1 % at the ≥ 100 electrons of a lit scene); then clipped to
// [0, 1], encoded with the sRGB transfer curve (IEC 61966-2-1) and rounded to 8 bits. The normal
// deviates come from Random123's Philox4x32-10 with the counter (pixel, frame, 0, 0) and the seed
// as key, through Box–Muller: the same seed gives the same clip on every machine, and any frame
// can be made alone.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace uphill {

struct ShutterTiming {
  double fps = 30;
  double exposure = 1.0 / 60;  // s, E ≤ 1/fps
  double readout = 0;          // s, rolling shutter's first-to-last-row time; 0: global shutter
  int height = 720;            // rows
  double t0 = 0;               // s, clip time of frame 0's first row's mid-exposure

  double FrameTime(int frame) const { return t0 + frame / fps; }
  double RowTime(int frame, double row) const { return FrameTime(frame) + row * readout / height; }
};

struct LightModel {
  double flicker_depth = 0;    // m, relative modulation of the light
  double flicker_hz = 100;     // Hz
  double flicker_phase = 0.4;  // rad
  double drift_depth = 0;      // d, relative amplitude of the exposure drift
  double drift_period = 2.5;   // s
  double drift_phase = 0;      // rad

  double Gain(double t) const;
  // ∫_a^b g(t) dt, s.
  double Integral(double a, double b) const;
};

struct SensorModel {
  double full_well = 4000;  // electrons at the white level
  double read_noise = 3;    // electrons rms
  std::uint64_t seed = 1;
  bool noise = true;

  // The 8-bit sRGB frame (CV_8UC3) of a linear frame (CV_32FC3, 1 = white level), the noise of
  // frame number `frame`.
  cv::Mat ToFrame8(const cv::Mat& linear, std::uint64_t frame) const;
};

// sRGB transfer curve (IEC 61966-2-1), linear [0, 1] -> encoded [0, 1].
double SrgbEncode(double linear);
double SrgbDecode(double encoded);

}  // namespace uphill
