// Importer of DBAT / PhotoModeler close-range projects (Börlin & Grussenmeyer's Damped Bundle
// Adjustment Toolbox), converted once into the FORMATS.md block files.
//
// Conventions converted here, in one place (CONVENTIONS.md):
// - Marks (`image_id, point_id, x, y[, sxy]`) are PhotoModeler pixels with the top-left CORNER of
//   the image at (0, 0); aerocal puts the centre of the top-left pixel there: col = x - 0.5,
//   row = y - 0.5.
// - DBAT cameras (`<cc>`, `<pp>` in mm from the top-left corner, y down, `<sensor>` W,H mm or
//   "auto,H", `<image>` W,H px, `<K>`, `<P>`) map to the 10-parameter model with
//   x0 = px - W p / 2, y0 = H p / 2 - py (photo frame: origin at the format centre, y up);
//   K1..K3, P1, P2 keep their values (DBAT's backward model 3 is the same correction form).
//   `cc` or `pp` of 0 mean "not known": the focal length and the format centre are used.
// - Rotations: DBAT's world-to-camera (Rx(w) Ry(p) Rz(k))^T equals CONVENTIONS' R^T, so angles
//   carry over. Initial EO files (`id, X, Y, Z, omega, phi, kappa`, degrees) and DBAT
//   camera_stations files (radians, whatever the header says) are both read. PhotoModeler
//   "Bundle Soln" exports list a station as `X Y Z a b c` with (a, b, c) = (kappa, phi, omega)
//   in degrees (checked against DBAT's camera_stations of the same project).
// - Control points `id, label, X, Y, Z[, sxyz]` (m); a missing sigma takes `control_sigma_m`.
#pragma once

#include "triangulation/block/block.h"

#include <string>

namespace aerocal::triangulation {

struct DbatImportOptions {
  std::string camera_xml;           // DBAT camera file (initial camera)
  std::string marks;                // markpts.txt
  std::string images;               // images.txt: id, path (image ids become file stems)
  std::string control;              // optional control file
  std::string initial_eo;           // `id, X, Y, Z, omega, phi, kappa` in degrees, or
  std::string photomodeler_export;  // a PhotoModeler bundle export with the stations
  double default_sigma_px = 1.0;    // where the marks have no sxy, > 0
  double control_sigma_m = 0.001;
};

/// Reads a DBAT project into a Project (camera id "cam1"); InputError("FILE:LINE: ...") on bad
/// input. Points without control become tie points; the frame is "as given".
Project ImportDbat(const DbatImportOptions& options);

/// The 10-parameter camera of a DBAT camera XML file.
calib::Camera ReadDbatCamera(const std::string& path);

}  // namespace aerocal::triangulation
