// A parameter block mounted on a carrier -- the angles of a mount, a lever arm, a time offset, the
// boresight of a rig head, a line camera or an IMU, a GNSS antenna -- enters an adjustment in one
// of three ways (BlockMode): held at its value, estimated freely, or estimated with its value as a
// weighted observation (a prior r = (x - value) / sigma, whitened, calib/residuals/prior.h).
// One enum, one rule for the prior's residual group, one JSON form, for every owner:
//
//   owner         blocks                                             group (PriorGroup)
//   platform      GNSS lever arm, GNSS time offset, IMU boresight    platform_prior
//   rig           head mounts, lever arms, time offsets, increments  rig_prior
//   line          line camera boresight and lever arm                line_prior
//   rig_stitch    increments and time offsets of rig stitching       rig_stitch_prior
//
// JSON form of one block (MountedBlockToJson / MountedBlockFromJson), in the caller's units
// (m, deg, ms as the key's suffix says):
//   {"mode": "fixed" | "free" | "weighted", "value": [..], "sigma": [.. or null]}
// `value` the estimate (the given value when fixed), `sigma` its a-posteriori sigma per entry,
// null when unknown (fixed, or no covariance).
#pragma once

#include "calib/problem/problem_builder.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace aerocal::calib {

/// How a mounted block enters the adjustment.
enum class BlockMode { kFixed, kFree, kWeighted };

/// "fixed" | "free" | "weighted" -> the mode; nullopt for any other text (case matters).
std::optional<BlockMode> ParseBlockMode(std::string_view text);
/// The mode given to `option` (a command-line option or a YAML key): ConfigError "OPTION must be
/// fixed, free or weighted (got 'TEXT')" otherwise (exit 2).
BlockMode BlockModeOption(const std::string& text, const std::string& option);
std::string_view BlockModeName(BlockMode mode);

/// The residual group of the priors of an owner's weighted blocks: OWNER + "_prior"
/// ("platform" -> "platform_prior"). Every owner names its group through this rule.
std::string PriorGroup(std::string_view owner);

/// Holds `block` at its current values when `mode` is kFixed; a free or weighted block stays free.
void ApplyBlockMode(ProblemBuilder& builder, BlockId block, BlockMode mode);

/// When `mode` is kWeighted: the prior (x - value) / sigma on every entry of `block` (`value` and
/// `sigma` (> 0) one per entry) in group PriorGroup(owner), labelled `label`; its id. -1 (nothing
/// added) for a fixed or free block.
ResidualId AddBlockPrior(ProblemBuilder& builder,
                         BlockId block,
                         BlockMode mode,
                         const std::vector<double>& value,
                         const std::vector<double>& sigma,
                         std::string_view owner,
                         const std::string& label);

/// A mounted block as its JSON form holds it (units of the key).
struct MountedBlockJson {
  BlockMode mode = BlockMode::kFixed;
  std::vector<double> value;
  std::vector<std::optional<double>> sigma;  // nullopt: unknown (JSON null)
};

/// The JSON form (header comment); a non-finite sigma is written null, as an unknown one.
nlohmann::json MountedBlockToJson(BlockMode mode,
                                  const Eigen::VectorXd& value,
                                  const std::optional<Eigen::VectorXd>& sigma);
/// Reads the JSON form; InputError naming `where` (a file and key) when a key is missing, the mode
/// is unknown, or value and sigma differ in length.
MountedBlockJson MountedBlockFromJson(const nlohmann::json& json, const std::string& where);

}  // namespace aerocal::calib
