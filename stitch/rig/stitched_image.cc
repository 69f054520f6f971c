#include "stitch/rig/stitched_image.h"

#include "calib/core/error.h"
#include "stitch/rig/feather_weights.h"
#include "stitch/rig/rig_convert.h"

#include <Eigen/Dense>

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

// One head on the virtual grid over its footprint box `region` (outside it the head covers
// nothing): its interpolated value (16 bit: DN x scale) and its blending weight (0: not covered).
struct HeadOnVirtual {
  VirtualRegion region;
  std::vector<std::uint8_t> value;  // 16-bit samples, native byte order (the projection's bytes)
  std::vector<std::uint8_t> weight;
};

// Head k's samples along one virtual row: value[c - first], weight[c - first] for columns
// first..last (none when the row misses the head's box).
struct HeadRow {
  const std::uint8_t* value = nullptr;  // 2 bytes per sample
  const std::uint8_t* weight = nullptr;
  int first = 0, last = -1;
  std::uint8_t Weight(int c) const { return c < first || c > last ? 0 : weight[c - first]; }
  std::uint16_t Value(int c) const {  // where Weight(c) > 0
    std::uint16_t v;
    std::memcpy(&v, value + 2 * static_cast<size_t>(c - first), 2);
    return v;
  }
};

HeadRow RowOf(const HeadOnVirtual& h, int r) {
  HeadRow row;
  const VirtualRegion& b = h.region;
  if (r < b.y0 || r >= b.y0 + b.height) return row;
  const size_t at = static_cast<size_t>(r - b.y0) * b.width;
  return {h.value.data() + 2 * at, h.weight.data() + at, b.x0, b.x0 + b.width - 1};
}

// std::clamp(std::round(x), 0.0, top) for a finite x and an integer top, without the library
// call: round half away from zero is trunc(x) + 1 when x - trunc(x) >= 0.5 (x >= 0; the fraction
// is exact in double); x <= 0 clamps to 0 (round gives 0, -0 or less) and x >= top - 0.5 to top.
double RoundClamped(double x, double top) {
  if (!(x > 0)) return 0.0;
  if (x >= top) return top;
  const double whole = static_cast<double>(static_cast<std::int64_t>(x));
  return x - whole >= 0.5 ? whole + 1.0 : whole;
}

// The head's raw pixels as a 16-bit raster (8-bit values x 256: the interpolation keeps 1/256 DN;
// 16-bit values as they are).
MemoryRaster AsSixteenBit(RasterSource* source) {
  const RasterInfo in = source->Info();
  MemoryRaster out({in.width, in.height, 1, 16});
  std::uint8_t* to = out.bytes().data();
  std::vector<std::uint8_t> row(in.RowBytes());
  for (int r = 0; r < in.height; ++r, to += 2 * static_cast<size_t>(in.width)) {
    if (in.bits == 16) {
      source->ReadWindow(0, r, in.width, 1, to);
      continue;
    }
    source->ReadWindow(0, r, in.width, 1, row.data());
    for (int c = 0; c < in.width; ++c) {
      const std::uint16_t s = static_cast<std::uint16_t>(row[c] << 8);
      std::memcpy(to + 2 * c, &s, 2);
    }
  }
  return out;
}

// True when no covered pixel lies on a side of the box that is not the format's edge.
bool CoverageInsideBox(const HeadProjection& p, int width, int height) {
  const VirtualRegion& b = p.region;
  const auto covered = [&](int x, int y) {
    return p.covered[static_cast<size_t>(y) * b.width + x] != 0;
  };
  for (int x = 0; x < b.width; ++x)
    if ((b.y0 > 0 && covered(x, 0)) || (b.y0 + b.height < height && covered(x, b.height - 1)))
      return false;
  for (int y = 0; y < b.height; ++y)
    if ((b.x0 > 0 && covered(0, y)) || (b.x0 + b.width < width && covered(b.width - 1, y)))
      return false;
  return true;
}

// Each head resampled once, alone, over its footprint's box, with its blending weights:
// min(distance to the border of its coverage, feather_px), at least 1 where covered.
std::vector<HeadOnVirtual> ProjectHeads(const RigConverter& converter,
                                        const std::vector<RasterSource*>& sources,
                                        const HeadMapCorrections& grids,
                                        const ResampleOptions& resample,
                                        int feather_px) {
  std::vector<HeadOnVirtual> on(sources.size());
  for (size_t k = 0; k < sources.size(); ++k) {
    MemoryRaster source = AsSixteenBit(sources[k]);
    HeadProjection projection =
        ProjectHeadFootprint(converter, static_cast<int>(k), grids.grids[k], &source, resample);
    const VirtualRegion& box = projection.region;
    on[k].region = box;
    on[k].value = std::move(projection.values.bytes());
    on[k].weight = FeatherWeights(projection.covered.data(), box.width, box.height, feather_px);
  }
  return on;
}

// Dodging: unknowns (g_k, o_k) of the non-reference heads, normal equations of the overlap
// equations (g_j I_j + o_j) - (g_k I_k + o_k) = 0 at every sample_step-th pixel (rows and
// columns). Each equation's coefficient vector a has at most four non-zero entries; only those
// products are added (the others add 0 exactly). Counts the samples per head into `report`.
void AccumulateBalance(const std::vector<HeadOnVirtual>& on,
                       const std::vector<int>& unknown,
                       int width,
                       int height,
                       int step,
                       double scale,
                       Eigen::MatrixXd* normal,
                       Eigen::VectorXd* rhs,
                       StitchedImageReport* report) {
  const int heads = static_cast<int>(on.size());
  std::vector<HeadRow> rows(heads);
  for (int r = 0; r < height; r += step) {
    for (int k = 0; k < heads; ++k) rows[k] = RowOf(on[k], r);
    for (int c = 0; c < width; c += step)
      for (int j = 0; j < heads; ++j) {
        if (rows[j].Weight(c) == 0) continue;
        for (int k = j + 1; k < heads; ++k) {
          if (rows[k].Weight(c) == 0) continue;
          // a . x = b, a over the unknowns; the reference head's value moves to b.
          int index[4], n = 0;
          double coefficient[4], b = 0.0;
          const auto put = [&](int h, double sign) {
            const double value = rows[h].Value(c) / scale;
            if (unknown[h] < 0) {
              b -= sign * value;
            } else {
              index[n] = 2 * unknown[h], coefficient[n++] = sign * value;
              index[n] = 2 * unknown[h] + 1, coefficient[n++] = sign;
            }
          };
          put(j, 1.0);
          put(k, -1.0);
          for (int p = 0; p < n; ++p) {
            for (int q = 0; q < n; ++q)
              (*normal)(index[q], index[p]) += coefficient[q] * coefficient[p];
            (*rhs)(index[p]) += coefficient[p] * b;
          }
          ++report->heads[j].samples;
          ++report->heads[k].samples;
        }
      }
  }
}

// The gains and offsets from the normal equations; every head at g = 1, o = 0 (with a warning)
// when a head has no overlap chain to the reference head.
void SolveBalance(const Eigen::MatrixXd& normal,
                  const Eigen::VectorXd& rhs,
                  const std::vector<int>& unknown,
                  const std::string& reference_head,
                  std::vector<double>* gain,
                  std::vector<double>* offset,
                  StitchedImageReport* report) {
  const int n = static_cast<int>(rhs.size());
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(normal);
  if (qr.rank() < n) {
    report->warnings.push_back(
        {"radiometry_not_determinable",
         "radiometric balance",
         NAN,
         NAN,
         "radiometric balance not determinable (a head has no overlap chain to the reference "
         "head " +
             reference_head + "): every head kept at gain 1, offset 0"});
    return;
  }
  const Eigen::VectorXd x = qr.solve(rhs);
  for (size_t k = 0; k < unknown.size(); ++k)
    if (unknown[k] >= 0) (*gain)[k] = x(2 * unknown[k]), (*offset)[k] = x(2 * unknown[k] + 1);
}

// Disagreement sums per head pair (j, k), j < k, over the pixels both cover.
struct PairSums {
  explicit PairSums(int heads)
      : heads(heads), sum(heads * heads), sum2(heads * heads), count(heads * heads) {}
  int heads;
  std::vector<double> sum, sum2;
  std::vector<long> count;
};

// The blended output with its mask, written in blocks of rows, and the disagreement before
// blending (the header comment).
void BlendAndWrite(const std::vector<HeadOnVirtual>& on,
                   const std::vector<double>& gain,
                   const std::vector<double>& offset,
                   double scale,
                   int bits,
                   int width,
                   int height,
                   RasterSink* image,
                   RasterSink* mask,
                   PairSums* pairs,
                   long* valid_pixels) {
  const int heads = static_cast<int>(on.size());
  const double top = bits == 8 ? 255.0 : 65535.0;
  const int bytes = bits / 8;
  const int block = std::max(1, std::min(64, height));
  std::vector<std::uint8_t> out_rows(static_cast<size_t>(block) * width * bytes);
  std::vector<std::uint8_t> mask_rows(static_cast<size_t>(block) * width);
  std::vector<double> balanced(heads);
  std::vector<HeadRow> rows(heads);
  for (int r0 = 0; r0 < height; r0 += block) {
    const int n_rows = std::min(block, height - r0);
    for (int r = r0; r < r0 + n_rows; ++r) {
      for (int k = 0; k < heads; ++k) rows[k] = RowOf(on[k], r);
      for (int c = 0; c < width; ++c) {
        double weighted = 0.0, weights = 0.0;
        for (int k = 0; k < heads; ++k) {
          const std::uint8_t w = rows[k].Weight(c);
          if (w == 0) continue;
          balanced[k] = gain[k] * (rows[k].Value(c) / scale) + offset[k];
          weighted += w * balanced[k];
          weights += w;
          for (int j = 0; j < k; ++j) {
            if (rows[j].Weight(c) == 0) continue;
            const double d = balanced[j] - balanced[k];
            pairs->sum[j * heads + k] += d;
            pairs->sum2[j * heads + k] += d * d;
            ++pairs->count[j * heads + k];
          }
        }
        const size_t o = static_cast<size_t>(r - r0) * width + c;
        const double v = weights > 0 ? RoundClamped(weighted / weights, top) : 0.0;
        if (bytes == 1) {
          out_rows[o] = static_cast<std::uint8_t>(v);
        } else {
          const std::uint16_t s = static_cast<std::uint16_t>(v);
          std::memcpy(&out_rows[2 * o], &s, 2);
        }
        mask_rows[o] = weights > 0 ? 255 : 0;
        *valid_pixels += weights > 0 ? 1 : 0;
      }
    }
    image->WriteRows(r0, n_rows, out_rows.data());
    mask->WriteRows(r0, n_rows, mask_rows.data());
  }
}

// Per head pair with overlap and over all pairs: RMS and mean of the disagreement.
void ReportZones(const calib::Rig& rig, const PairSums& pairs, StitchedImageReport* report) {
  const int heads = pairs.heads;
  report->overall.zone = "all";
  double all_sum = 0.0, all_sum2 = 0.0;
  for (int j = 0; j < heads; ++j)
    for (int k = j + 1; k < heads; ++k) {
      const long m = pairs.count[j * heads + k];
      if (m == 0) continue;
      OverlapDisagreement z;
      z.zone = rig.heads[j].id + rig.heads[k].id;
      z.pixels = m;
      z.mean_dn = pairs.sum[j * heads + k] / m;
      z.rms_dn = std::sqrt(pairs.sum2[j * heads + k] / m);
      report->zones.push_back(z);
      report->overall.pixels += m;
      all_sum += pairs.sum[j * heads + k];
      all_sum2 += pairs.sum2[j * heads + k];
    }
  if (report->overall.pixels > 0) {
    report->overall.mean_dn = all_sum / report->overall.pixels;
    report->overall.rms_dn = std::sqrt(all_sum2 / report->overall.pixels);
  }
}

}  // namespace

HeadProjection ProjectHeadOntoVirtual(const RigConverter& converter,
                                      int head,
                                      const MapCorrectionGrid& grid,
                                      RasterSource* source,
                                      const ResampleOptions& resample) {
  const calib::Camera all = RigExposureAsSubimageCamera(converter);
  calib::Camera one = all;
  one.subimages = {all.subimages[head]};
  const VirtualRegion region =
      resample.region.Empty() ? VirtualRegion{0, 0, all.width_px, all.height_px} : resample.region;
  const int width = region.width, height = region.height;
  const std::vector<MapCorrectionGrid> grids = {grid};
  const RasterInfo info = source->Info();
  HeadProjection out{region, MemoryRaster({width, height, 1, info.bits}), {}};
  MemoryRaster covered({width, height, 1, 8});
  ResampleVirtualImage(one, {source}, &out.values, resample, grids, &covered);
  out.covered = std::move(covered.bytes());
  return out;
}

VirtualRegion HeadFootprintBox(const RigConverter& converter, int head, int margin_px) {
  const calib::Camera& h = converter.rig().heads[head].camera;
  const calib::Camera& v = converter.rig().virtual_camera.camera;
  constexpr int kStepPx = 16;
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  const auto add = [&](double u, double w) {
    const auto p = converter.VirtualFromHead(head, Eigen::Vector2d(u, w));
    if (!p || !std::isfinite(p->x()) || !std::isfinite(p->y())) return false;
    x0 = std::min(x0, p->x()), x1 = std::max(x1, p->x());
    y0 = std::min(y0, p->y()), y1 = std::max(y1, p->y());
    return true;
  };
  const double right = h.width_px - 1.0, bottom = h.height_px - 1.0;
  bool ok = true;
  for (double u = 0; u < right && ok; u += kStepPx) ok = add(u, 0) && add(u, bottom);
  for (double w = 0; w < bottom && ok; w += kStepPx) ok = add(0, w) && add(right, w);
  ok = ok && add(right, bottom);
  if (!ok) return {};
  const int bx0 = std::max(0, static_cast<int>(std::floor(std::max(x0, -1e9))) - margin_px);
  const int by0 = std::max(0, static_cast<int>(std::floor(std::max(y0, -1e9))) - margin_px);
  const int bx1 =
      std::min(v.width_px - 1, static_cast<int>(std::ceil(std::min(x1, 1e9))) + margin_px);
  const int by1 =
      std::min(v.height_px - 1, static_cast<int>(std::ceil(std::min(y1, 1e9))) + margin_px);
  if (bx1 < bx0 || by1 < by0) return {};
  return {bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1};
}

HeadProjection ProjectHeadFootprint(const RigConverter& converter,
                                    int head,
                                    const MapCorrectionGrid& grid,
                                    RasterSource* source,
                                    const ResampleOptions& resample) {
  const calib::Camera& v = converter.rig().virtual_camera.camera;
  ResampleOptions boxed = resample;
  boxed.region = HeadFootprintBox(converter, head);
  if (!boxed.region.Empty()) {
    HeadProjection p = ProjectHeadOntoVirtual(converter, head, grid, source, boxed);
    if (CoverageInsideBox(p, v.width_px, v.height_px)) return p;
  }
  ResampleOptions whole = resample;
  whole.region = {};
  return ProjectHeadOntoVirtual(converter, head, grid, source, whole);
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
  ResampleOptions resample;
  resample.interpolation = options.interpolation;
  resample.fill = 0.0;
  resample.strip_rows = options.strip_rows;
  const std::vector<HeadOnVirtual> on =
      ProjectHeads(converter, sources, grids, resample, options.feather_px);

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
  std::vector<int> unknown(heads, -1);
  for (int k = 0, n = 0; k < heads; ++k)
    if (k != reference) unknown[k] = n++;
  const int n = 2 * (heads - 1);
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  AccumulateBalance(
      on, unknown, width, height, options.sample_step_px, scale, &normal, &rhs, &report);
  std::vector<double> gain(heads, 1.0), offset(heads, 0.0);
  if (options.balance && n > 0)
    SolveBalance(normal, rhs, unknown, rig.reference_head, &gain, &offset, &report);
  for (int k = 0; k < heads; ++k)
    report.heads[k].gain = gain[k], report.heads[k].offset_dn = offset[k];

  PairSums pairs(heads);
  BlendAndWrite(on,
                gain,
                offset,
                scale,
                first.bits,
                width,
                height,
                image,
                mask,
                &pairs,
                &report.valid_pixels);
  ReportZones(rig, pairs, &report);
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
