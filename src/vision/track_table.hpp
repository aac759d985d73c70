// Track: the ball's measured positions, one row per video frame, as `uphill track` writes them
// (and `uphill analyse-track` reads them).
//
// CSV format (the one `uphill track` writes): the header starts exactly with
//   frame,t,u,v,radius_px,x,z,quality
// and may have more columns after these. Of those, u_px, u_x and u_outline_px are read when
// present (`uphill track` writes them), each ≥ 0 and filled in every frame with a position: the
// standard uncertainty of a found frame's centre, raw pixels (each image axis) and millimetres
// along the rails, and the part of it that the frame's outline shows (px; 0: not stated; see
// TrackFrame); others are ignored. frame: integer ≥ 0, strictly increasing;
// t: seconds from the container's timestamps, finite, strictly increasing; u, v: the projected
// ball centre in raw pixels; radius_px: pixels, > 0; x, z: the centre in millimetres in the
// apparatus frame (docs/physics.md "Frame and apparatus"); quality: a confidence in [0, 1]. Cells are plain numbers (the
// units are fixed by the format, not written in the cells).
//
// Lost frames: a frame where the ball was not found keeps its row with t filled, u … z empty and
// quality 0. It is kept here as a frame with found = false: never interpolated, never invented.
// A row with some of u … z empty and others filled, or with quality > 0 and empty positions, is
// an error (the tracker either found the ball or did not). A frame with positions but quality 0
// is read as lost (zero confidence), its numbers ignored.
//
// Errors: InputError naming the file, the spreadsheet row (header = row 1) and the column with
// the rule broken, for the first bad row; the whole file is refused, since a track with a broken
// row is not a track one should trust. Units: the Track holds SI (x, z in metres, t in seconds).
#pragma once

#include <istream>
#include <string>
#include <vector>

namespace uphill {

struct TrackFrame {
  int row = 0;         // spreadsheet row of the CSV (header = 1), for messages
  long frame = 0;      // frame number, from 0
  double t = 0;        // s
  bool found = false;  // false: the ball was not found in this frame (fields below unused)
  double u = 0, v = 0, radius_px = 0;  // raw pixels
  double x = 0, z = 0;                  // m, apparatus frame
  double quality = 0;                   // (0, 1] when found
  // Standard uncertainty of the centre: raw pixels (each image axis) and m along the rails; 0
  // where the track does not state it (no u_px, u_x columns).
  double u_px = 0, u_x = 0;
  // The centre's spread over the parts of its outline, raw pixels (BallObservation::
  // outline_spread_px): an error the frames at rest share; 0 where not stated.
  double u_outline_px = 0;
};

struct Track {
  std::string source;  // file name or "<stdin>"
  std::vector<TrackFrame> frames;
  // The standard uncertainty of a rolling shutter's row delay (measured, or assumed where it
  // could not be), s per row: a frame's time t = timestamp + v·readout/H is then uncertain by
  // v·row_delay_u, in every frame alike (one readout). From the sidecar's readout_u_s /
  // image_height_px (ReadTrackFile); 0: none (a global shutter, or a readout given).
  double row_delay_u = 0;

  std::size_t found_count() const;
};

// The exact leading columns of the format.
const std::vector<std::string>& TrackColumns();

Track ReadTrack(std::istream& in, const std::string& source);
// Opens `path` ("-" reads stdin); InputError naming the file when it cannot be read. Reads the
// sidecar `path`.json too when there is one (data/README.md, "Track CSV"): InputError naming it
// and the field when it is not JSON or readout_u_s / image_height_px are out of range.
Track ReadTrackFile(const std::string& path);

}  // namespace uphill
