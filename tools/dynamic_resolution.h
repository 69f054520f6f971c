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
/// `sub_image` where `quality mtf --sub-image / --virtual` named them), `bars`, `stars` and
/// `resampling_loss` (ResamplingLossJson). InputError naming the file for one that is not a
/// quality result or lacks a table.
nlohmann::json DynamicResolutionJson(const std::vector<std::string>& paths);

/// Per axis (x, y) where both raw sub-images and the virtual image have a combined MTF50: the raw
/// sub-images' mean m_r = (1/n) sum m_i with u(m_r) = sqrt(sum u_i^2) / n, the virtual image's m_v
/// (the mean likewise when several virtual results are given), the loss m_r - m_v with
/// u = sqrt(u(m_r)^2 + u(m_v)^2) and U = 2 u, and both relative to m_r in percent. The sub-images
/// are taken as measured independently: their shared type-B part, which the difference partly
/// cancels, is counted in full, so U is on the safe side. `axes` is the section's `axes` array.
nlohmann::json ResamplingLossJson(const nlohmann::json& axes);

}  // namespace aerocal::tools
