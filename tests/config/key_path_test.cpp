// Documents built in memory (config/key_path.h): diagnostics name the key path of the node, for
// every kind of node; the same text without the mark is an ordinary file.
#include "config/key_path.h"

#include <gtest/gtest.h>

#include "config/yaml_reader.h"

using namespace isolink;
using namespace isolink::config;

namespace {
const std::string kJson =
    "{\n \"cable\": {\n  \"lenght\": 4\n },\n \"frames\": [\n  \"a\",\n  5\n ]\n}";
}

TEST(KeyPath, UnknownKeyIsNamedByItsPath) {
  auto doc = YamlDoc::from_text(key_path_document(kJson), "spec");
  ASSERT_TRUE(doc.ok()) << doc.status().message();
  double length = 0;
  Status s = read_map(*doc, doc->root()["cable"], "cable",
                      {{"length", read_quantity(*doc, Unit::kMetre, Rule::kPositive, &length)}});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(),
            "cable.lenght: error: unknown key 'cable.lenght' in 'cable' (known keys: length)");
}

TEST(KeyPath, MapsValuesListItemsAndTheRoot) {
  auto doc = YamlDoc::from_text(key_path_document(kJson), "spec");
  ASSERT_TRUE(doc.ok());
  const YAML::Node& root = doc->root();
  EXPECT_EQ(doc->error(root["cable"], "m").message(), "cable: error: m");
  EXPECT_EQ(doc->error(root["cable"]["lenght"], "m").message(), "cable.lenght: error: m");
  EXPECT_EQ(doc->error(root["frames"], "m").message(), "frames: error: m");
  EXPECT_EQ(doc->error(root["frames"][1], "m").message(), "frames[1]: error: m");
  EXPECT_EQ(doc->error(root, "m").message(), "spec: error: m");
}

TEST(KeyPath, WithoutTheMarkAFileKeepsLinesAndColumns) {
  auto plain = YamlDoc::from_text(kJson, "spec.json");
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->error(plain->root()["frames"][1], "m").message(),
            "spec.json:7:3: error: m\n   5\n   ^");
  const SourceFile file = *SourceFile::FromText("x", kJson);
  EXPECT_FALSE(is_key_path_document(file));
  EXPECT_EQ(key_path_at(file, 3, 3), std::nullopt);
}
