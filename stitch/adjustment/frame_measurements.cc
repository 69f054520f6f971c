#include "stitch/adjustment/frame_measurements.h"

#include "calib/core/error.h"

#include <map>
#include <set>

namespace aerocal::stitch {

std::vector<FrameMeasurements> GroupByFrame(const calib::Camera& camera,
                                            const std::vector<StitchObservation>& rows,
                                            const std::string& file) {
  std::map<std::string, int> reference_index;
  for (size_t i = 0; i < camera.reference_points.size(); ++i)
    reference_index[camera.reference_points[i].id] = static_cast<int>(i);

  // Rows per frame, keeping the order of first appearance of frames and points.
  std::vector<std::string> frame_order;
  std::map<std::string, std::vector<const StitchObservation*>> by_frame;
  for (const auto& row : rows) {
    auto [it, inserted] = by_frame.try_emplace(row.frame);
    if (inserted) frame_order.push_back(row.frame);
    it->second.push_back(&row);
  }

  std::vector<FrameMeasurements> frames;
  for (const auto& frame_id : frame_order) {
    FrameMeasurements frame;
    frame.frame = frame_id;
    std::vector<std::string> point_order;
    std::map<std::string, std::vector<const StitchObservation*>> by_point;
    for (const StitchObservation* row : by_frame[frame_id]) {
      const std::string where =
          SourceRef{file, row->line}.ToString() + ": frame " + frame_id + ", point " + row->point;
      const int k = camera.SubimageIndex(row->subimage);
      if (k < 0)
        throw InputError(where + ": sub-image '" + row->subimage + "' is not in the camera");
      auto [it, inserted] = by_point.try_emplace(row->point);
      if (inserted) point_order.push_back(row->point);
      for (const StitchObservation* other : it->second)
        if (other->subimage == row->subimage)
          throw InputError(where + ": measured twice in sub-image " + row->subimage +
                           (other->line > 0 ? " (also on line " + std::to_string(other->line) + ")"
                                            : std::string()));
      it->second.push_back(row);
    }
    std::set<std::string> measured_references;
    for (const auto& point : point_order) {
      const auto& obs = by_point[point];
      const auto ref = reference_index.find(point);
      if (ref != reference_index.end()) {
        const calib::ReferencePoint& rp = camera.reference_points[ref->second];
        for (const StitchObservation* row : obs) {
          if (row->subimage != rp.subimage)
            throw InputError(SourceRef{file, row->line}.ToString() + ": frame " + frame.frame +
                             ", point " + point + ": reference point of sub-image " + rp.subimage +
                             " measured in sub-image " + row->subimage);
          frame.references.push_back({point,
                                      camera.SubimageIndex(rp.subimage),
                                      {row->u, row->v},
                                      {rp.U, rp.V},
                                      row->sigma_px,
                                      true});
        }
        measured_references.insert(point);
        continue;
      }
      if (obs.size() < 2) {
        ++frame.single_ray_points;
        continue;
      }
      TieMeasurement tie;
      tie.point = point;
      for (const StitchObservation* row : obs)
        tie.rays.push_back({camera.SubimageIndex(row->subimage), {row->u, row->v}, row->sigma_px});
      frame.ties.push_back(std::move(tie));
    }
    for (const auto& rp : camera.reference_points)
      if (!measured_references.count(rp.id))
        frame.references.push_back({rp.id,
                                    camera.SubimageIndex(rp.subimage),
                                    {rp.u, rp.v},
                                    {rp.U, rp.V},
                                    rp.sigma_px,
                                    false});
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace aerocal::stitch
