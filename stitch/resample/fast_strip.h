// The fast path of ResampleVirtualImage (virtual_image.h) for one strip: bilinear, one band, no
// correction grids. Same coverage, same positions to 1e-5 px and the same rounding as the
// reference path; what changes is how the work is organised:
//
// - per virtual row, each sub-image's covered columns come in closed form (CoveredColumns); their
//   ends cut the row into intervals seen by the same set of sub-images. An interval seen by none
//   is filled, one seen by one sub-image is sampled straight into the output row, and only the
//   overlap bands (two or more) are summed in floats and averaged;
// - positions are 32.32 fixed point stepped along the row (bilinear_run.h). For an affine mapping
//   they are exact to 2^-32 px per step over the whole row. For a projectivity they are exact at
//   nodes every L columns and linear between them, L chosen per row from the closed-form second
//   derivative u'' = -2 wa (xa wb - xb wa) / w^3 (x = xa U + xb, w = wa U + wb along the row):
//   the chord leaves the curve by at most L^2 max|u''| / 8 <= kChordPx.
//
// Rows are independent and computed by the same code whatever the thread, so the output is
// bit-identical for any thread count.
#pragma once

#include "stitch/resample/resample_window.h"

#include <atomic>
#include <cstdint>
#include <vector>

namespace aerocal::stitch::internal {

inline constexpr double kChordPx = 1e-5;  // largest position error of the linearised projectivity

/// Resamples the columns `columns` of virtual rows [y0, y0 + rows) into `strip` (rows of
/// columns.Count() samples of T, 8 or 16 bit); `width` is the virtual format's, and each pixel is
/// the one the whole row gives (the same runs and nodes). `fill` is the value of uncovered pixels,
/// already in T's range. With `coverage` (rows of columns.Count() bytes): 255 where a sub-image
/// covers the pixel, 0 elsewhere. Adds the covered and overlap pixel counts.
template <typename T>
void ResampleStripFast(const std::vector<Window>& windows,
                       float fill,
                       int width,
                       ColumnSpan columns,
                       int y0,
                       int rows,
                       std::uint8_t* strip,
                       std::uint8_t* coverage,
                       std::atomic<long>* covered,
                       std::atomic<long>* overlap);

}  // namespace aerocal::stitch::internal
