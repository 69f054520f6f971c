#include "calib/problem/mounted_block.h"

#include "calib/core/error.h"
#include "calib/residuals/prior.h"

#include <cmath>

namespace aerocal::calib {

std::optional<BlockMode> ParseBlockMode(std::string_view text) {
  if (text == "fixed") return BlockMode::kFixed;
  if (text == "free") return BlockMode::kFree;
  if (text == "weighted") return BlockMode::kWeighted;
  return std::nullopt;
}

BlockMode BlockModeOption(const std::string& text, const std::string& option) {
  const auto mode = ParseBlockMode(text);
  if (!mode) throw ConfigError(option + " must be fixed, free or weighted (got '" + text + "')");
  return *mode;
}

std::string_view BlockModeName(BlockMode mode) {
  switch (mode) {
    case BlockMode::kFree:
      return "free";
    case BlockMode::kWeighted:
      return "weighted";
    case BlockMode::kFixed:
      break;
  }
  return "fixed";
}

std::string PriorGroup(std::string_view owner) { return std::string(owner) + "_prior"; }

void ApplyBlockMode(ProblemBuilder& builder, BlockId block, BlockMode mode) {
  if (mode == BlockMode::kFixed) builder.FixBlock(block);
}

ResidualId AddBlockPrior(ProblemBuilder& builder,
                         BlockId block,
                         BlockMode mode,
                         const std::vector<double>& value,
                         const std::vector<double>& sigma,
                         std::string_view owner,
                         const std::string& label) {
  if (mode != BlockMode::kWeighted) return -1;
  AEROCAL_CHECK(static_cast<int>(value.size()) == builder.BlockSize(block) &&
                value.size() == sigma.size())
      << "prior of " << builder.BlockName(block) << ": one value and one sigma per entry";
  return builder.AddResidual(
      PriorGroup(owner), PriorCostFunction::Create(value, sigma), {block}, label);
}

nlohmann::json MountedBlockToJson(BlockMode mode,
                                  const Eigen::VectorXd& value,
                                  const std::optional<Eigen::VectorXd>& sigma) {
  nlohmann::json j = {{"mode", BlockModeName(mode)}};
  j["value"] = nlohmann::json::array();
  j["sigma"] = nlohmann::json::array();
  for (int i = 0; i < value.size(); ++i) {
    j["value"].push_back(value(i));
    const bool known = sigma && std::isfinite((*sigma)(i));
    j["sigma"].push_back(known ? nlohmann::json((*sigma)(i)) : nlohmann::json());
  }
  return j;
}

MountedBlockJson MountedBlockFromJson(const nlohmann::json& json, const std::string& where) {
  const auto fail = [&](const std::string& what) { throw InputError(where + ": " + what); };
  if (!json.is_object()) fail("a mounted block is an object {mode, value, sigma}");
  for (const char* key : {"mode", "value", "sigma"})
    if (!json.contains(key)) fail(std::string("missing key '") + key + "'");
  MountedBlockJson out;
  const auto& mode = json["mode"];
  const auto parsed = mode.is_string() ? ParseBlockMode(mode.get<std::string>()) : std::nullopt;
  if (!parsed) fail("mode must be fixed, free or weighted (got " + mode.dump() + ")");
  out.mode = *parsed;
  const auto& value = json["value"];
  const auto& sigma = json["sigma"];
  if (!value.is_array() || !sigma.is_array() || value.size() != sigma.size())
    fail("value and sigma must be arrays of equal length");
  for (size_t i = 0; i < value.size(); ++i) {
    if (!value[i].is_number()) fail("value[" + std::to_string(i) + "] must be a number");
    out.value.push_back(value[i].get<double>());
    if (sigma[i].is_null())
      out.sigma.emplace_back();
    else if (sigma[i].is_number())
      out.sigma.emplace_back(sigma[i].get<double>());
    else
      fail("sigma[" + std::to_string(i) + "] must be a number or null");
  }
  return out;
}

}  // namespace aerocal::calib
