// The "dynamic image resolution" section (issue 36 item 5) gathered from `aerocal quality`
// results: the certificate's (certificate.json, `certificate --quality`, `flight --certificate
// --quality`) and the flight result's (result.json of `flight --quality`, which report.html shows).
// Values are copied from the quality results; the one number computed here is the resampling
// loss, the virtual image's MTF50 against the raw sub-images' mean per axis.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::tools {

/// The section from the results of `aerocal quality mtf` / `bars` / `star` at `paths`: `sources`,
/// `method`, `edges` and `axes` (each with the source, and `image_kind` raw / virtual and
/// `sub_image` where `quality mtf --sub-image / --virtual` named them; an edge found from a target
/// also its `target`, `image_id`, `position_virtual_px` and a raw one its `resampling` block),
/// `virtual_format_px` (the first result's that has it), `bars`, `stars`, `resampling_loss`
/// (ResamplingLossJson) and `resampling_per_sub_image` (ResamplingPerSubImageJson). InputError
/// naming the file for one that is not a quality result or lacks a table.
nlohmann::json DynamicResolutionJson(const std::vector<std::string>& paths);

/// Per axis (x, y) where both raw sub-images and the virtual image have a combined MTF50: the raw
/// sub-images' mean m_r = (1/n) sum m_i with u(m_r) = sqrt(sum u_i^2) / n, the virtual image's m_v
/// (the mean likewise when several virtual results are given), the loss m_r - m_v with
/// u = sqrt(u(m_r)^2 + u(m_v)^2) and U = 2 u, and both relative to m_r in percent. The sub-images
/// are taken as measured independently: their shared type-B part, which the difference partly
/// cancels, is counted in full, so U is on the safe side. `axes` is the section's `axes` array;
/// the axes of `quality mtf --targets` results (those with an `image_id`: one exposure's edges,
/// compared per edge in their `resampling` blocks) are left out.
nlohmann::json ResamplingLossJson(const nlohmann::json& axes);

/// Per raw sub-image and axis, over the section's edges measured with `quality mtf --targets
/// --sub-image --mapping` (those with a `resampling` block): `edges`, the plain means of the raw
/// MTF50, of the virtual MTF50 and the measured loss (over the `virtual_measured` edges measured in
/// the virtual image too), and of the predicted losses (at the mapping's shifts and at uniform
/// phases), in percent of each edge's raw MTF50. The report's per-sub-image table.
nlohmann::json ResamplingPerSubImageJson(const nlohmann::json& edges);

}  // namespace aerocal::tools
