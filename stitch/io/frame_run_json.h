// One frame's stitching run (FrameRun: the adjustment and, with --model auto, every candidate of
// the model choice) as JSON, LOSSLESS: every field, doubles written in the shortest text that
// reads back to the same bits (nlohmann's), non-finite values as "nan" / "inf" / "-inf". This is
// how `aerocal batch` hands a frame adjusted in one process to the merge in another, which must
// give the single-process result to the last bit; it is an exchange file, not a result for people
// (those are FrameResultToJson's keys).
#pragma once

#include "stitch/adjustment/flight_stability.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::stitch {

/// Every field of `run`; FrameRunFromJson(FrameRunToJson(r)) == r field by field.
nlohmann::json FrameRunToJson(const FrameRun& run);

/// The run back; InputError("PATH: ...") for a document that is not one (`path` names it).
FrameRun FrameRunFromJson(const nlohmann::json& document, const std::string& path);

}  // namespace aerocal::stitch
