// The JSON-Schema subset of calib/core/json_schema.h: references to another schema file (bundled
// by ReadJsonSchema), allOf, "#" (the whole schema); the finding type every result's `warnings`
// uses (calib/core/finding.h) and the list of result kinds (calib/core/result_file.h).
#include "calib/core/json_schema.h"

#include "calib/core/error.h"
#include "calib/core/finding.h"
#include "calib/core/result_file.h"
#include "calib/problem/mounted_block.h"
#include "calib/problem/solve_statistics_json.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <iterator>
#include <map>
#include <string>

namespace aerocal {
namespace {

using nlohmann::json;

void Write(const std::string& path, const json& j) { std::ofstream(path) << j.dump(); }

// The InputError text of ValidateJson, "" when the document validates.
std::string Refusal(const json& document, const json& schema) {
  try {
    ValidateJson(document, schema, "r.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(JsonSchema, ResolvesDefinitionsOfAnotherFileAndTheirOwnReferences) {
  testing::TempDir dir("aerocal_json_schema");
  Write(dir.File("common.schema.json"),
        {{"definitions",
          {{"sigma", {{"type", {"number", "null"}}, {"minimum", 0}}},
           {"pair", {{"type", "array"}, {"items", {{"$ref", "#/definitions/sigma"}}}}}}}});
  Write(dir.File("inner.schema.json"),
        {{"type", "object"},
         {"required", {"n"}},
         {"properties", {{"n", {{"type", "integer"}}}, {"self", {{"$ref", "#"}}}}}});
  Write(dir.File("kind.schema.json"),
        {{"type", "object"},
         {"additionalProperties", false},
         {"properties",
          {{"s", {{"$ref", "common.schema.json#/definitions/pair"}}},
           {"inner", {{"$ref", "inner.schema.json"}}},
           {"both", {{"allOf", {{{"type", "integer"}}, {{"minimum", 2}}}}}}}}});
  const json schema = ReadJsonSchema(dir.File("kind.schema.json"));
  EXPECT_EQ(Refusal({{"s", {0.1, nullptr}}, {"inner", {{"n", 1}}}, {"both", 3}}, schema), "");
  // A reference inside the other file resolves within that file ("#/definitions/sigma").
  EXPECT_EQ(Refusal({{"s", {-1.0}}}, schema), "r.json: s[0]: must be >= 0 (got -1.0)");
  // "#" inside inner.schema.json is inner's whole schema, not kind's.
  EXPECT_EQ(Refusal({{"inner", {{"n", 1}, {"self", {{"m", 1}}}}}}, schema),
            "r.json: inner.self.n: missing");
  EXPECT_EQ(Refusal({{"both", 1}}, schema), "r.json: both: must be >= 2 (got 1)");
  EXPECT_EQ(Refusal({{"other", 1}}, schema), "r.json: other: not allowed here (got 1)");
  // A reference to a file that is not there: an installation fault (LogicError), not bad input.
  Write(dir.File("broken.schema.json"), {{"$ref", "missing.schema.json#/definitions/x"}});
  EXPECT_THROW(ReadJsonSchema(dir.File("broken.schema.json")), LogicError);
}

// Every kind a command writes has its schema, and every schema reads (its references resolve).
TEST(JsonSchema, EveryResultKindHasASchema) {
  for (std::string_view kind : kResultKinds) {
    const std::string path = testing::SchemaPath(std::string(kind));
    ASSERT_TRUE(std::ifstream(path).good()) << kind << " has no schema " << path;
    const json schema = ReadJsonSchema(path);
    // The schema names its kind: a document of another kind does not validate.
    EXPECT_NE(Refusal({{"kind", "not_" + std::string(kind)}}, schema), "") << kind;
  }
  EXPECT_THROW(ResultText("no_such_kind", json::object()), LogicError);
}

// WriteResult streams the document into the file instead of building its text: the file holds
// exactly ResultText's bytes, for every indent (0 is pretty with no indentation, -1 one line),
// with non-ASCII text, nested arrays, doubles and nulls; a bad kind or invalid UTF-8 leaves no
// file.
TEST(ResultFile, WrittenFileIsResultTextByteForByte) {
  testing::TempDir dir("aerocal_result_file");
  const json document = {
      {"b", {1.0 / 3.0, nullptr, -0.0, 1e-300, 12345678901234.5}},
      {"a", {{"name", "Gau\u00df-Kr\u00fcger \"x\"\n"}, {"empty", json::array()}}},
      {"n", 7},
      {"o", json::object()}};
  for (int indent : {2, 1, 0, -1}) {
    const std::string path = dir.File("r" + std::to_string(indent + 1) + ".json");
    WriteResult(path, "adjust", document, indent);
    std::ifstream in(path, std::ios::binary);
    const std::string written((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(written, ResultText("adjust", document, indent)) << "indent " << indent;
  }
  EXPECT_THROW(WriteResult(dir.File("k.json"), "no_such_kind", document), LogicError);
  EXPECT_THROW(WriteResult(dir.File("u.json"), "adjust", {{"s", "\xff"}}), json::type_error);
  EXPECT_FALSE(std::ifstream(dir.File("k.json")).good());
  EXPECT_FALSE(std::ifstream(dir.File("u.json")).good());
}

// Each kind carries its own schema_version (docs/schema/CHANGES.md): version 3 raised the kinds
// whose keys changed (adjust, pushbroom, rig_stitch; later certificate) and left the others at 2,
// so their files stay readable. The writer stamps the kind's version; a reader refuses another by
// the kind's number.
TEST(ResultKinds, EachKindHasItsOwnVersion) {
  for (const char* kind : {"adjust", "pushbroom", "rig_stitch", "certificate"})
    EXPECT_EQ(ResultSchemaVersion(kind), 3) << kind;
  for (const char* kind : {"flight", "stitch", "rig_error_analysis"})
    EXPECT_EQ(ResultSchemaVersion(kind), 2) << kind;
  EXPECT_THROW(ResultSchemaVersion("no_such_kind"), LogicError);
  ASSERT_EQ(kResultKinds.size(), kResultKindTable.size());
  for (size_t i = 0; i < kResultKinds.size(); ++i) {
    EXPECT_EQ(kResultKinds[i], kResultKindTable[i].name);
    const json stamped = json::parse(ResultText(kResultKinds[i], json::object()));
    EXPECT_EQ(stamped["schema_version"], kResultKindTable[i].schema_version) << kResultKinds[i];
  }
  const auto refusal = [](const json& document) -> std::string {
    try {
      CheckResult(document, "r.json", {"adjust", "stitch"}, "a test");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(refusal({{"kind", "stitch"}, {"schema_version", 2}}), "");
  EXPECT_EQ(refusal({{"kind", "adjust"}, {"schema_version", 3}}), "");
  EXPECT_EQ(refusal({{"kind", "adjust"}, {"schema_version", 2}}),
            "r.json: schema_version is 2, expected 3 (kind \"adjust\")");
  EXPECT_EQ(refusal({{"kind", "stitch"}, {"schema_version", 3}}),
            "r.json: schema_version is 3, expected 2 (kind \"stitch\")");
}

// The one form of a block mounted on a carrier (calib/problem/mounted_block.h) is the schema's
// mounted_block: three entries for a mount or lever arm, one for a time offset, an unknown sigma
// null; the wrong number of entries (keys are checked in name order: sigma first) or an unknown
// mode does not validate.
TEST(MountedBlock, OneShapeInTheCommonSchema) {
  const json common = ReadJsonSchema(testing::SchemaPath("common"));
  const auto schema = [&](const std::string& name) {
    return json({{"$ref", "#/definitions/" + name}, {"definitions", common["definitions"]}});
  };
  const json mount = calib::MountedBlockToJson(
      calib::BlockMode::kFree, Eigen::Vector3d(0.1, 1.0, -0.2), Eigen::VectorXd::Constant(3, 1e-3));
  EXPECT_EQ(Refusal(mount, schema("mounted_block_3")), "");
  const json held =
      calib::MountedBlockToJson(calib::BlockMode::kFixed, Eigen::VectorXd::Zero(1), std::nullopt);
  EXPECT_EQ(held, json({{"mode", "fixed"}, {"value", {0.0}}, {"sigma", {nullptr}}}));
  EXPECT_EQ(Refusal(held, schema("mounted_block_1")), "");
  EXPECT_EQ(Refusal(held, schema("mounted_block_3")),
            "r.json: sigma: expected at least 3 items (got [null])");
  EXPECT_EQ(Refusal(mount, schema("mounted_block_1")),
            "r.json: sigma: expected at most 1 items (got [0.001,0.001,0.001])");
  json loose = mount;
  loose["mode"] = "loose";
  EXPECT_NE(Refusal(loose, schema("mounted_block")).find("mode: expected one of"),
            std::string::npos);
}

TEST(Finding, OneShapeWithNullForAMissingFigure) {
  const json common = ReadJsonSchema(testing::SchemaPath("common"));
  const json finding = {{"$ref", "#/definitions/finding"}, {"definitions", common["definitions"]}};
  const json with = FindingToJson({"group_rms", "image", 4.5, 3.0, "too large"});
  EXPECT_EQ(with,
            json({{"name", "group_rms"},
                  {"subject", "image"},
                  {"value", 4.5},
                  {"limit", 3.0},
                  {"message", "too large"}}));
  EXPECT_EQ(Refusal(with, finding), "");
  Finding without{"group_stability", "group 2", NAN, NAN, "group 2: c differs"};
  const json listed = FindingsToJson({without});
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_TRUE(listed[0]["value"].is_null());
  EXPECT_TRUE(listed[0]["limit"].is_null());
  EXPECT_EQ(Refusal(listed[0], finding), "");
}

// The one writer of the solve statistics: the keys and types common.schema.json defines, NaN RMS
// of an empty group as null.
TEST(SolveStatistics, KeysOfTheCommonSchema) {
  calib::SolveReport report;
  report.converged = true;
  report.iterations = 4;
  report.termination = "CONVERGENCE";
  report.linear_solver = "dense_schur";
  report.redundancy = 12;
  report.seconds = 0.5;
  report.groups = {{"image", 3, 20, 18.0, 0.9486832980505138}, {"gnss", 0, 0, 0.0, NAN}};
  const json j = calib::SolveStatisticsToJson(report);
  const json common = ReadJsonSchema(testing::SchemaPath("common"));
  const std::map<std::string, std::string> definition = {{"redundancy", "redundancy"},
                                                         {"iterations", "iterations"},
                                                         {"converged", "converged"},
                                                         {"termination", "termination"},
                                                         {"linear_solver", "linear_solver"},
                                                         {"seconds", "seconds"},
                                                         {"groups", "residual_groups"}};
  ASSERT_EQ(j.size(), definition.size()) << j.dump();
  for (const auto& [key, name] : definition) {
    const json schema = {{"$ref", "#/definitions/" + name}, {"definitions", common["definitions"]}};
    EXPECT_EQ(Refusal(j.at(key), schema), "") << key;
  }
  EXPECT_EQ(j["groups"][0],
            json({{"name", "image"}, {"n", 20}, {"rms_sigma", 0.9486832980505138}}));
  EXPECT_TRUE(j["groups"][1]["rms_sigma"].is_null());
}

}  // namespace
}  // namespace aerocal
