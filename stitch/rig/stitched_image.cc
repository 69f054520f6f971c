#include "stitch/rig/stitched_image.h"

#include "calib/core/error.h"
#include "stitch/rig/rig_convert.h"

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace aerocal::stitch {

void StitchedImageOptions::Validate() const {
  if (sample_step_px < 1 || sample_step_px > 64)
    throw ConfigError("stitched image: sample_step_px must be within 1..64 (got " +
                      std::to_string(sample_step_px) + ")");
  if (feather_px < 1 || feather_px > 255)
    throw ConfigError("stitched image: feather_px must be within 1..255 (got " +
                      std::to_string(feather_px) + ")");
  if (strip_rows < 1) throw ConfigError("stitched image: strip_rows must be > 0");
}

namespace {

// One head on the virtual grid: its interpolated value (16 bit: DN x scale) and its blending
// weight (0: not covered).
struct HeadOnVirtual {
  std::vector<std::uint16_t> value;
  std::vector<std::uint8_t> weight;
};

// The head's raw pixels as a 16-bit raster (8-bit values x 256: the interpolation keeps 1/256 DN).
MemoryRaster AsSixteenBit(RasterSource* source, double scale) {
  const RasterInfo in = source->Info();
  MemoryRaster out({in.width, in.height, 1, 16});
  std::vector<std::uint8_t> row(in.RowBytes());
  for (int r = 0; r < in.height; ++r) {
    source->ReadWindow(0, r, in.width, 1, row.data());
    for (int c = 0; c < in.width; ++c) {
      double v;
      if (in.bits == 8) {
        v = row[c];
      } else {
        std::uint16_t s;
        std::memcpy(&s, &row[2 * c], 2);
        v = s;
      }
      out.Set(c, r, 0, v * scale);
    }
  }
  return out;
}

}  // namespace

HeadProjection ProjectHeadOntoVirtual(const RigConverter& converter,
                                      int head,
                                      const MapCorrectionGrid& grid,
                                      RasterSource* source,
                                      const ResampleOptions& resample) {
  const calib::Camera all = RigExposureAsSubimageCamera(converter);
  const int width = all.width_px, height = all.height_px;
  calib::Camera one = all;
  one.subimages = {all.subimages[head]};
  const std::vector<MapCorrectionGrid> grids = {grid};
  const RasterInfo info = source->Info();
  HeadProjection out{MemoryRaster({width, height, 1, info.bits}), {}};
  ResampleVirtualImage(one, {source}, &out.values, resample, grids);
  MemoryRaster ones({info.width, info.height, 1, 8});
  std::fill(ones.bytes().begin(), ones.bytes().end(), 0xFF);
  MemoryRaster covered({width, height, 1, 8});
  ResampleOptions coverage = resample;
  coverage.fill = 0.0;
  ResampleVirtualImage(one, {&ones}, &covered, coverage, grids);
  out.covered.resize(static_cast<size_t>(width) * height);
  for (size_t i = 0; i < out.covered.size(); ++i)
    out.covered[i] = covered.bytes()[i] > 127 ? 255 : 0;
  return out;
}

StitchedImageReport MakeStitchedImage(const RigConverter& converter,
                                      const std::vector<RasterSource*>& sources,
                                      const StitchedImageOptions& options,
                                      RasterSink* image,
                                      RasterSink* mask) {
  options.Validate();
  const calib::Rig& rig = converter.rig();
  const int heads = static_cast<int>(rig.heads.size());
  AEROCAL_CHECK(static_cast<int>(sources.size()) == heads) << sources.size() << " sources";
  const RasterInfo first = sources.front()->Info();
  for (int k = 0; k < heads; ++k) {
    const RasterInfo info = sources[k]->Info();
    if (info.bands != 1 || info.bits != first.bits)
      throw InputError("head " + rig.heads[k].id +
                       ": the stitched image needs one-band images of one depth (got " +
                       std::to_string(info.bands) + " bands, " + std::to_string(info.bits) +
                       " bit)");
  }
  const double scale = first.bits == 8 ? 256.0 : 1.0;
  const calib::Camera all = RigExposureAsSubimageCamera(converter);
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  const int width = all.width_px, height = all.height_px;
  const size_t pixels = static_cast<size_t>(width) * height;
  ResampleOptions resample;
  resample.interpolation = options.interpolation;
  resample.fill = 0.0;
  resample.strip_rows = options.strip_rows;

  // Each head resampled once, alone, onto the virtual grid, with its coverage.
  std::vector<HeadOnVirtual> on(heads);
  for (int k = 0; k < heads; ++k) {
    MemoryRaster source = AsSixteenBit(sources[k], scale);
    const HeadProjection projection =
        ProjectHeadOntoVirtual(converter, k, grids.grids[k], &source, resample);
    const MemoryRaster& values = projection.values;
    cv::Mat inside(height, width, CV_8UC1, const_cast<std::uint8_t*>(projection.covered.data()));
    cv::Mat distance;
    cv::distanceTransform(inside, distance, cv::DIST_L2, 3);
    on[k].value.resize(pixels);
    std::memcpy(on[k].value.data(), values.bytes().data(), 2 * pixels);
    on[k].weight.resize(pixels);
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) {
        const float d = distance.at<float>(r, c);
        on[k].weight[static_cast<size_t>(r) * width + c] =
            inside.at<std::uint8_t>(r, c) == 0 ? 0
                                               : static_cast<std::uint8_t>(std::clamp(
                                                     std::lround(d), 1L, long(options.feather_px)));
      }
  }

  StitchedImageReport report;
  report.width_px = width;
  report.height_px = height;
  report.bits = first.bits;
  const int reference = rig.ReferenceIndex();
  report.heads.resize(heads);
  for (int k = 0; k < heads; ++k) {
    report.heads[k].head = rig.heads[k].id;
    report.heads[k].reference = k == reference;
  }
  const auto value = [&](int k, size_t at) { return on[k].value[at] / scale; };

  // Dodging: unknowns (g_k, o_k) of the non-reference heads, normal equations of the overlap
  // equations (g_j I_j + o_j) - (g_k I_k + o_k) = 0 at the sampled pixels.
  std::vector<int> unknown(heads, -1);
  for (int k = 0, n = 0; k < heads; ++k)
    if (k != reference) unknown[k] = n++;
  const int n = 2 * (heads - 1);
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (int r = 0; r < height; r += options.sample_step_px)
    for (int c = 0; c < width; c += options.sample_step_px) {
      const size_t at = static_cast<size_t>(r) * width + c;
      for (int j = 0; j < heads; ++j) {
        if (on[j].weight[at] == 0) continue;
        for (int k = j + 1; k < heads; ++k) {
          if (on[k].weight[at] == 0) continue;
          // a . x = b, a over the unknowns; the reference head's value moves to b.
          Eigen::VectorXd a = Eigen::VectorXd::Zero(n);
          double b = 0.0;
          const auto put = [&](int h, double sign) {
            if (unknown[h] < 0) {
              b -= sign * value(h, at);
            } else {
              a(2 * unknown[h]) = sign * value(h, at);
              a(2 * unknown[h] + 1) = sign;
            }
          };
          put(j, 1.0);
          put(k, -1.0);
          normal.noalias() += a * a.transpose();
          rhs += a * b;
          ++report.heads[j].samples;
          ++report.heads[k].samples;
        }
      }
    }
  std::vector<double> gain(heads, 1.0), offset(heads, 0.0);
  if (options.balance && n > 0) {
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(normal);
    if (qr.rank() < n) {
      report.warnings.push_back(
          {"radiometry_not_determinable",
           "radiometric balance",
           NAN,
           NAN,
           "radiometric balance not determinable (a head has no overlap chain to the reference "
           "head " +
               rig.reference_head + "): every head kept at gain 1, offset 0"});
    } else {
      const Eigen::VectorXd x = qr.solve(rhs);
      for (int k = 0; k < heads; ++k)
        if (unknown[k] >= 0) gain[k] = x(2 * unknown[k]), offset[k] = x(2 * unknown[k] + 1);
    }
  }
  for (int k = 0; k < heads; ++k)
    report.heads[k].gain = gain[k], report.heads[k].offset_dn = offset[k];

  // Disagreement before blending, per head pair, and the blended output with its mask.
  std::vector<double> sum(heads * heads, 0.0), sum2(heads * heads, 0.0);
  std::vector<long> count(heads * heads, 0);
  const double top = first.bits == 8 ? 255.0 : 65535.0;
  const int bytes = first.bits / 8;
  const int block = std::max(1, std::min(64, height));
  std::vector<std::uint8_t> out_rows(static_cast<size_t>(block) * width * bytes);
  std::vector<std::uint8_t> mask_rows(static_cast<size_t>(block) * width);
  std::vector<double> balanced(heads);
  for (int r0 = 0; r0 < height; r0 += block) {
    const int rows = std::min(block, height - r0);
    for (int r = r0; r < r0 + rows; ++r)
      for (int c = 0; c < width; ++c) {
        const size_t at = static_cast<size_t>(r) * width + c;
        double weighted = 0.0, weights = 0.0;
        for (int k = 0; k < heads; ++k) {
          if (on[k].weight[at] == 0) continue;
          balanced[k] = gain[k] * value(k, at) + offset[k];
          weighted += on[k].weight[at] * balanced[k];
          weights += on[k].weight[at];
          for (int j = 0; j < k; ++j) {
            if (on[j].weight[at] == 0) continue;
            const double d = balanced[j] - balanced[k];
            sum[j * heads + k] += d;
            sum2[j * heads + k] += d * d;
            ++count[j * heads + k];
          }
        }
        const size_t o = static_cast<size_t>(r - r0) * width + c;
        const double v = weights > 0 ? std::clamp(std::round(weighted / weights), 0.0, top) : 0.0;
        if (bytes == 1) {
          out_rows[o] = static_cast<std::uint8_t>(v);
        } else {
          const std::uint16_t s = static_cast<std::uint16_t>(v);
          std::memcpy(&out_rows[2 * o], &s, 2);
        }
        mask_rows[o] = weights > 0 ? 255 : 0;
        report.valid_pixels += weights > 0 ? 1 : 0;
      }
    image->WriteRows(r0, rows, out_rows.data());
    mask->WriteRows(r0, rows, mask_rows.data());
  }
  report.overall.zone = "all";
  double all_sum = 0.0, all_sum2 = 0.0;
  for (int j = 0; j < heads; ++j)
    for (int k = j + 1; k < heads; ++k) {
      const long m = count[j * heads + k];
      if (m == 0) continue;
      OverlapDisagreement z;
      z.zone = rig.heads[j].id + rig.heads[k].id;
      z.pixels = m;
      z.mean_dn = sum[j * heads + k] / m;
      z.rms_dn = std::sqrt(sum2[j * heads + k] / m);
      report.zones.push_back(z);
      report.overall.pixels += m;
      all_sum += sum[j * heads + k];
      all_sum2 += sum2[j * heads + k];
    }
  if (report.overall.pixels > 0) {
    report.overall.mean_dn = all_sum / report.overall.pixels;
    report.overall.rms_dn = std::sqrt(all_sum2 / report.overall.pixels);
  }
  for (int k = 0; k < heads; ++k)
    if (k != reference && report.heads[k].samples == 0)
      report.warnings.push_back({"head_without_overlap",
                                 rig.heads[k].id,
                                 NAN,
                                 NAN,
                                 "head " + rig.heads[k].id + " overlaps no other head"});
  return report;
}

}  // namespace aerocal::stitch
