#include <gtest/gtest.h>

#include <filesystem>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::app {
namespace {

std::vector<std::string> validFiles() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(testing::dataDir())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("valid", 0) == 0 && entry.path().extension() == ".xml") {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

Application loadOrFail(std::string_view xml) {
  Result<Application> app = loadApplicationString(xml, "saved.xml");
  EXPECT_TRUE(app.ok()) << app.error().message;
  return app.ok() ? std::move(app).value() : Application{};
}

TEST(SaveApplication, LoadThenSaveReproducesEveryLibraryWrittenFileByteForByte) {
  const std::vector<std::string> files = validFiles();
  ASSERT_GE(files.size(), 4u);
  for (const std::string& file : files) {
    const std::string original = testing::readFile(file);
    const Result<Application> app = loadApplicationString(original, file);
    ASSERT_TRUE(app.ok()) << app.error().message;
    EXPECT_EQ(saveApplication(*app), original) << file;
  }
}

TEST(SaveApplication, ModelBuiltInCodeSurvivesSaveAndLoad) {
  Application app;
  app.name = "built in code";
  app.hosts = {Host{"a", "10.0.0.1", {}}, Host{"b", "10.0.0.2", {}}};
  Module source;
  source.id = "src";
  source.package = "core";
  source.type = "source";
  source.host = "b";
  setParam(source.params, "count", "4");
  setParam(source.params, "label", "tab\there & \"quoted\" <x>\nnext line");
  Module sink;
  sink.id = "sink";
  sink.package = "core";
  sink.type = "sink";
  sink.host = "a";
  sink.inputs.push_back(InputConfig{"in", 1, InputMode::Latest, {}});
  app.modules = {source, sink};
  Filter pass;
  pass.id = "pass";
  pass.type = "passthrough";
  Filter plugged;
  plugged.id = "plugged";
  plugged.type = "every-nth";
  plugged.plugin = "filters/libmine.so";
  app.filters = {pass, plugged};
  Connection first;
  first.from = {"src", "out"};
  first.to = {"pass", "in"};
  first.capacity = 16;
  first.policy = QueuePolicy::DropNewest;
  Connection second;
  second.from = {"pass", "out"};
  second.to = {"sink", "in"};
  app.connections = {first, second};
  app.editor = {EditorNode{"src", 0.1, -2.75, {}}, EditorNode{"sink", 1e-7, 3e12, {}}};

  const std::string saved = saveApplication(app);
  const Application loaded = loadOrFail(saved);
  EXPECT_EQ(loaded.name, app.name);
  ASSERT_EQ(loaded.hosts.size(), 2u);
  EXPECT_EQ(loaded.hosts[1].address, "10.0.0.2");
  ASSERT_EQ(loaded.modules.size(), 2u);
  EXPECT_EQ(loaded.modules[0].host, "b");
  EXPECT_EQ(loaded.modules[1].host, "a");
  EXPECT_EQ(paramString(loaded.modules[0].params, "label", ""),
            "tab\there & \"quoted\" <x>\nnext line");
  ASSERT_EQ(loaded.modules[1].inputs.size(), 1u);
  EXPECT_EQ(loaded.modules[1].inputs[0].initialMessages, 1);
  EXPECT_EQ(loaded.modules[1].inputs[0].mode, InputMode::Latest);
  ASSERT_EQ(loaded.filters.size(), 2u);
  EXPECT_EQ(loaded.filters[0].host, "a");
  EXPECT_EQ(loaded.filters[0].plugin, "");
  EXPECT_EQ(loaded.filters[1].plugin, "filters/libmine.so");
  EXPECT_NE(saved.find(R"(<filter id="plugged" type="every-nth" plugin="filters/libmine.so"/>)"),
            std::string::npos)
      << saved;
  ASSERT_EQ(loaded.connections.size(), 2u);
  EXPECT_EQ(toString(loaded.connections[0].from), "src.out");
  EXPECT_EQ(loaded.connections[0].capacity, 16);
  EXPECT_EQ(loaded.connections[0].policy, QueuePolicy::DropNewest);
  ASSERT_EQ(loaded.editor.size(), 2u);
  EXPECT_EQ(loaded.editor[0].x, 0.1);
  EXPECT_EQ(loaded.editor[0].y, -2.75);
  EXPECT_EQ(loaded.editor[1].x, 1e-7);
  EXPECT_EQ(loaded.editor[1].y, 3e12);
  EXPECT_EQ(saveApplication(loaded), saved);
  // Without the plugin loaded, its filter type is unknown; everything else is valid.
  const auto problems = validate(loaded, testing::testCatalog());
  ASSERT_EQ(problems.size(), 1u) << formatDiagnostics(problems);
  EXPECT_NE(problems[0].message.find("unknown filter type 'every-nth'"), std::string::npos);
}

TEST(SaveApplication, WritesTheCanonicalFormLeavingDefaultsOut) {
  Application app;
  app.name = "defaults";
  Module module;
  module.id = "m";
  module.package = "core";
  module.type = "relay";
  module.inputs.push_back(InputConfig{"in", 0, InputMode::Fifo, {}});
  app.modules = {module};
  Connection loop;
  loop.from = {"m", "out"};
  loop.to = {"m", "in"};
  app.connections = {loop};
  app.editor = {EditorNode{"m", 0, 0, {}}};
  EXPECT_EQ(saveApplication(app),
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<application name=\"defaults\" version=\"1\">\n"
            "  <modules>\n"
            "    <module id=\"m\" package=\"core\" type=\"relay\">\n"
            "      <input port=\"in\"/>\n"
            "    </module>\n"
            "  </modules>\n"
            "  <connections>\n"
            "    <connection from=\"m.out\" to=\"m.in\"/>\n"
            "  </connections>\n"
            "  <editor>\n"
            "    <node ref=\"m\"/>\n"
            "  </editor>\n"
            "</application>\n");
}

TEST(SaveApplication, DoesNotWriteTheImplicitHost) {
  const Application app = loadOrFail(
      "<application name=\"a\">\n  <modules>\n"
      "    <module id=\"m\" package=\"core\" type=\"relay\"/>\n"
      "  </modules>\n</application>\n");
  ASSERT_EQ(app.hosts.size(), 1u);
  const std::string saved = saveApplication(app);
  EXPECT_EQ(saved.find("host"), std::string::npos) << saved;
}

TEST(SaveApplication, HandWrittenFileBecomesCanonicalThenStaysStable) {
  const Application app = loadOrFail(R"(<?xml version='1.0'?>
<!-- written by hand -->
<application version='1' name='hand'>
  <hosts><host address='127.0.0.1' id='main'/><host id='gpu' address='10.1.1.1'/></hosts>
  <modules>
    <module type='source' package='core' id='s' host='main'>
      <param value='1' name='count'/></module>
    <module type='sink' id='t' package='core' host='gpu'><input mode='fifo' port='in' initial-messages='0'/></module>
  </modules>
  <connections><connection to='t.in' from='s.out' capacity='0' policy='block'/></connections>
</application>)");
  const std::string canonical = saveApplication(app);
  // The comment stays, before the root as written (issue 20: comments survive edits).
  EXPECT_EQ(canonical,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<!-- written by hand -->\n"
            "<application name=\"hand\" version=\"1\">\n"
            "  <hosts>\n"
            "    <host id=\"main\"/>\n"
            "    <host id=\"gpu\" address=\"10.1.1.1\"/>\n"
            "  </hosts>\n"
            "  <modules>\n"
            "    <module id=\"s\" package=\"core\" type=\"source\">\n"
            "      <param name=\"count\" value=\"1\"/>\n"
            "    </module>\n"
            "    <module id=\"t\" package=\"core\" type=\"sink\" host=\"gpu\">\n"
            "      <input port=\"in\"/>\n"
            "    </module>\n"
            "  </modules>\n"
            "  <connections>\n"
            "    <connection from=\"s.out\" to=\"t.in\"/>\n"
            "  </connections>\n"
            "</application>\n");
  EXPECT_EQ(saveApplication(loadOrFail(canonical)), canonical);
}

TEST(SaveApplication, SaveApplicationFileWritesTheSameText) {
  const Application app = loadOrFail(testing::readFile(testing::dataDir() + "/valid_cluster.xml"));
  const std::string path =
      (std::filesystem::temp_directory_path() / "vrflow_app_save_test.xml").string();
  ASSERT_TRUE(saveApplicationFile(app, path).ok());
  EXPECT_EQ(testing::readFile(path), saveApplication(app));
  std::filesystem::remove(path);
}

TEST(SaveApplication, SaveApplicationFileFailsWithThePathWhenTheFolderIsMissing) {
  const Status status = saveApplicationFile(Application{}, "/nonexistent/folder/app.xml");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message.rfind("/nonexistent/folder/app.xml: error: cannot write", 0), 0u)
      << status.error().message;
}

}  // namespace
}  // namespace vrflow::app
