// XML comments, notes and frames through load, edit and save.
#include <gtest/gtest.h>

#include <regex>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::app {
namespace {

// Every `<!--...-->` of an XML text, in order.
std::vector<std::string> commentsIn(const std::string& xml) {
  static const std::regex comment("<!--([\\s\\S]*?)-->");
  std::vector<std::string> found;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), comment);
       it != std::sregex_iterator(); ++it) {
    found.push_back((*it)[1].str());
  }
  return found;
}

Application load(const std::string& xml, const std::string& name = "app.xml") {
  std::vector<Diagnostic> problems;
  Result<Application> app = loadApplicationString(xml, name, &problems);
  EXPECT_TRUE(app.ok()) << (app.ok() ? "" : app.error().message);
  EXPECT_TRUE(problems.empty()) << formatDiagnostics(problems);
  return app.ok() ? std::move(app).value() : Application{};
}

std::vector<Diagnostic> loadProblems(std::string_view xml) {
  std::vector<Diagnostic> problems;
  const Result<Application> app = loadApplicationString(xml, "app.xml", &problems);
  EXPECT_TRUE(app.ok());
  return problems;
}

TEST(Comments, EachCommentIsKeptWithTheElementItPrecedes) {
  const Application app =
      load(testing::readFile(testing::dataDir() + "/valid_commented.xml"), "valid_commented.xml");
  EXPECT_EQ(app.comments, Comments({" Before the root: what this file is for.\n     Second line "
                                    "of the same comment. "}));
  ASSERT_EQ(app.modules.size(), 2u);
  EXPECT_EQ(app.modules[0].comments, Comments({" the producer "}));
  EXPECT_EQ(app.modules[0].params[0].comments, Comments({" four messages, then it ends "}));
  EXPECT_EQ(app.modules[0].endComments, Comments({" after the last parameter "}));
  EXPECT_EQ(app.modules[1].inputs[0].comments,
            Comments({" one message before the first iteration "}));
  EXPECT_EQ(app.connections[0].comments, Comments({" data "}));
  const SectionComments* modules = findSectionComments(app, "modules");
  ASSERT_NE(modules, nullptr);
  EXPECT_EQ(modules->before, Comments({" before the modules "}));
  EXPECT_EQ(modules->end, Comments({" at the end of the modules "}));
  EXPECT_EQ(findSectionComments(app, "connections"), nullptr);
  EXPECT_EQ(app.endComments, Comments({" last words inside the root "}));
  EXPECT_EQ(app.afterComments, Comments({" after the root "}));
}

TEST(Comments, EditingAParameterOfThePaperSceneKeepsEveryComment) {
  const std::string path = testing::sourceDir() + "/examples/paper_scene/paper_scene_fluid.xml";
  const std::string original = testing::readFile(path);
  Application app = load(original, path);
  Module* net = findModule(app, "net");
  ASSERT_NE(net, nullptr);
  setParam(net->params, "mass", "90");
  // A module added and one removed: the comments of the others stay where they were.
  app.modules.erase(app.modules.begin() + 1);  // contacts, which has no comment
  const std::string saved = saveApplication(app);
  EXPECT_NE(saved.find("<param name=\"mass\" value=\"90\"/>"), std::string::npos);
  const std::vector<std::string> before = commentsIn(original);
  ASSERT_GE(before.size(), 5u);
  EXPECT_EQ(commentsIn(saved), before);
  // Each comment still precedes the same element.
  for (const char* kept : {"The net weighs its true 8 kg", "The liquid: animator"}) {
    const std::size_t at = saved.find(kept);
    ASSERT_NE(at, std::string::npos) << kept;
    const std::size_t next = saved.find("<module id=\"", at);
    const std::size_t nextBefore = original.find("<module id=\"", original.find(kept));
    EXPECT_EQ(saved.substr(next, 30), original.substr(nextBefore, 30)) << kept;
  }
  // Saving what was saved changes nothing.
  EXPECT_EQ(saveApplication(load(saved, path)), saved);
}

TEST(Comments, AHandWrittenFileKeepsItsCommentsInTheCanonicalForm) {
  const std::string xml = R"(<application name="x">
<!-- hosts first -->
<hosts><host id="a"/><!-- end of hosts --></hosts>
<modules>
<module id="m" package="core" type="source" host="a"><param name="count" value="1"/></module>
</modules>
</application>
)";
  const std::string saved = saveApplication(load(xml));
  EXPECT_EQ(saved, R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="x" version="1">
  <!-- hosts first -->
  <hosts>
    <host id="a"/>
    <!-- end of hosts -->
  </hosts>
  <modules>
    <module id="m" package="core" type="source">
      <param name="count" value="1"/>
    </module>
  </modules>
</application>
)");
}

TEST(EditorSection, NotesAndFramesAreReadWithTheirDefaults) {
  const Application app =
      load(testing::readFile(testing::dataDir() + "/valid_commented.xml"), "valid_commented.xml");
  ASSERT_EQ(app.notes.size(), 1u);
  EXPECT_EQ(app.notes[0].id, "why");
  EXPECT_EQ(app.notes[0].x, 10);
  EXPECT_EQ(app.notes[0].y, 200);
  EXPECT_EQ(app.notes[0].width, 240);
  EXPECT_EQ(app.notes[0].height, 80);  // the default
  EXPECT_EQ(app.notes[0].text, "Source feeds the sink.\nSecond line & a <tag>.");
  ASSERT_EQ(app.frames.size(), 2u);
  EXPECT_EQ(app.frames[0].title, "Pipeline");
  EXPECT_EQ(app.frames[0].color, "#3366cc");
  EXPECT_EQ(app.frames[0].width, 500);
  EXPECT_EQ(app.frames[0].comments, Comments({" a frame around both "}));
  EXPECT_EQ(app.frames[1].id, "empty");
  EXPECT_EQ(app.frames[1].width, 400);
  EXPECT_EQ(app.frames[1].height, 300);
  EXPECT_TRUE(app.frames[1].color.empty());
}

TEST(EditorSection, NotesAndFramesBuiltInCodeSurviveSaveAndLoad) {
  Application app;
  app.name = "notes";
  EditorNote note;
  note.id = "n1";
  note.x = -3.25;
  note.text = "a & b\n<c>\n";
  app.notes.push_back(note);
  EditorFrame frame;
  frame.id = "f1";
  frame.title = "Group \"one\"";
  frame.height = 120;
  frame.color = "#00ff00";
  app.frames.push_back(frame);
  const std::string saved = saveApplication(app);
  const Application again = load(saved);
  ASSERT_EQ(again.notes.size(), 1u);
  EXPECT_EQ(again.notes[0].text, note.text);
  EXPECT_EQ(again.notes[0].x, -3.25);
  ASSERT_EQ(again.frames.size(), 1u);
  EXPECT_EQ(again.frames[0].title, frame.title);
  EXPECT_EQ(again.frames[0].height, 120);
  EXPECT_EQ(again.frames[0].color, "#00ff00");
  EXPECT_EQ(saveApplication(again), saved);
}

TEST(EditorSection, ANoteOrFrameIdUsedTwiceIsOneErrorAtTheSecond) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application>
  <editor>
    <note id="a">first</note>
    <frame id="a"/>
  </editor>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 4, 12, "<frame> id 'a' is used twice (first at line 3)");
}

TEST(EditorSection, ABadNumberOrSizeOrColourIsReportedAtItsAttribute) {
  EXPECT_ONLY_ERROR_AT(loadProblems("<application>\n  <editor>\n    <note id=\"a\" x=\"left\"/>\n"
                                    "  </editor>\n</application>\n"),
                       3, 18, "must be a finite number");
  EXPECT_ONLY_ERROR_AT(loadProblems("<application>\n  <editor>\n    <frame id=\"a\" width=\"0\"/>\n"
                                    "  </editor>\n</application>\n"),
                       3, 19, "width must be above 0");
  EXPECT_ONLY_ERROR_AT(
      loadProblems("<application>\n  <editor>\n    <frame id=\"a\" color=\"red\"/>\n"
                   "  </editor>\n</application>\n"),
      3, 19, "color 'red' must be written #rrggbb");
  EXPECT_ONLY_ERROR_AT(loadProblems("<application>\n  <editor>\n    <note id=\"a\"><b/></note>\n"
                                    "  </editor>\n</application>\n"),
                       3, 18, "unknown element <b> in <note>");
}

}  // namespace
}  // namespace vrflow::app
