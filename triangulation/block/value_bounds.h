// Physical bounds of the block files' values (triangulation/README.md "Value bounds"), shared by
// every block-file reader (block_io, the pushbroom pos.csv): object coordinates within 1e8 m (UTM
// northings, geocentric metres and degrees fit), angles within one turn either way, pixel
// coordinates within 1e7 px, sigmas positive and at most 1e6 m / 360 deg / 1e4 px.
#pragma once

namespace aerocal::triangulation::bounds {

constexpr double kMaxCoordinateM = 1e8;
constexpr double kMaxAngleDeg = 360.0;
constexpr double kMaxPixel = 1e7;
constexpr double kMaxSigmaM = 1e6;
constexpr double kMaxSigmaDeg = 360.0;
constexpr double kMaxSigmaPx = 1e4;
constexpr double kMaxVelocityMps = 1e4;

}  // namespace aerocal::triangulation::bounds
