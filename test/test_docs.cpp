// docs/scene-format.md cannot fall behind the loader: every element, attribute
// and setting the loader accepts (sceneVocabulary(), settingKeys()) is written
// there. An element needs a heading of its own ("### `<clearance>`") or, for
// the children of one (<origin>, <shape>, <end>...), its parent's section; every
// attribute (and setting key) must stand as a word inside a `code span` of that
// section.
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "nscd_sim/scene_loader.hpp"
#include "test_support.hpp"

namespace {

std::string readDoc() {
  std::ifstream f(nscd_test::scenePath("docs/scene-format.md"));
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The section under the heading that names `<element>` (up to the next heading
// of level 2 or 3); empty if there is no such heading.
std::string section(const std::string& doc, const std::string& element) {
  std::istringstream in(doc);
  std::string line, out;
  bool inside = false;
  while (std::getline(in, line)) {
    const bool heading = line.rfind("## ", 0) == 0 || line.rfind("### ", 0) == 0;
    if (heading) inside = line.find("`<" + element + ">`") != std::string::npos;
    if (line.rfind("```", 0) == 0) continue;  // a code fence would pair the span quotes wrongly
    if (inside) out += line + "\n";
  }
  return out;
}

// The words of every `code span` of text.
std::set<std::string> codeWords(const std::string& text) {
  std::set<std::string> words;
  static const std::regex span("`([^`]+)`");
  static const std::regex word("[A-Za-z0-9_]+");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), span); it != std::sregex_iterator(); ++it) {
    const std::string s = (*it)[1];
    for (auto w = std::sregex_iterator(s.begin(), s.end(), word); w != std::sregex_iterator(); ++w)
      words.insert(w->str());
  }
  return words;
}

}  // namespace

TEST(Docs, SceneFormatNamesEveryElementAndAttribute) {
  const std::string doc = readDoc();
  ASSERT_FALSE(doc.empty()) << "docs/scene-format.md not found";
  int checked = 0;
  for (const nscd::SceneElementVocabulary& v : nscd::sceneVocabulary()) {
    std::string text = section(doc, v.element);
    if (text.empty()) text = section(doc, v.parent);  // <origin> of <joint>, <shape> of <contact>...
    ASSERT_FALSE(text.empty()) << "no section for <" << v.element << "> (or its parent <" << v.parent
                               << ">) in docs/scene-format.md";
    EXPECT_NE(text.find("<" + v.element), std::string::npos)
        << "<" << v.element << "> is not named in its section";
    const std::set<std::string> words = codeWords(text);
    for (const std::string& a : v.attributes) {
      EXPECT_TRUE(words.count(a)) << "attribute '" << a << "' of <" << v.element << "> "
                                  << v.variant << " is not documented in its section";
      ++checked;
    }
    if (!v.variant.empty())
      EXPECT_TRUE(words.count(v.variant)) << "<" << v.element << " type=\"" << v.variant
                                          << "\"> is not documented";
  }
  for (const std::string& k : nscd::settingKeys())
    EXPECT_TRUE(codeWords(section(doc, "simulation")).count(k))
        << "setting '" << k << "' is not documented under <simulation>";
  EXPECT_GT(checked, 50);
}

// docs/performance.md is written by scripts/performance.sh from
// scripts/templates/performance_template.md: everything but the generated parts (@NAME@ in
// the template) must be the template's text, in its order, and every generated part must
// have been filled in. A hand-written section edited into the page only would be lost at
// the next regeneration; a figure typed into the template has no command behind it, so
// the template states how each generated part is made and the page when and where.
TEST(Docs, PerformancePageMatchesItsTemplate) {
  const auto read = [](const char* path) {
    std::ifstream f(nscd_test::scenePath(path));
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  const std::string page = read("docs/performance.md"), tmpl = read("scripts/templates/performance_template.md");
  ASSERT_FALSE(page.empty());
  ASSERT_FALSE(tmpl.empty());
  const std::regex placeholder("@[A-Z][A-Z0-9_]*@");
  size_t at = 0;
  int chunks = 0;
  for (std::sregex_token_iterator it(tmpl.begin(), tmpl.end(), placeholder, -1), end; it != end; ++it) {
    const std::string chunk = *it;
    if (chunk.empty()) continue;
    const size_t found = page.find(chunk, at);
    ASSERT_NE(found, std::string::npos)
        << "docs/performance.md lacks (or reorders) this text of the template:\n"
        << chunk.substr(0, 300);
    at = found + chunk.size();
    ++chunks;
  }
  EXPECT_GE(chunks, 12);
  std::smatch left;
  EXPECT_FALSE(std::regex_search(page, left, placeholder))
      << "docs/performance.md still holds the placeholder " << left.str() << ": regenerate it";
  // The run that made the page: its date and its commit.
  EXPECT_TRUE(std::regex_search(page, std::regex("Last run: [0-9]{4}-[0-9]{2}-[0-9]{2} [0-9:]+ UTC, commit `[0-9a-f]{7,}`")))
      << "docs/performance.md does not say when and at which commit it was generated";
  // Dated work-log sections belong to the git log, not to a reference page.
  EXPECT_FALSE(std::regex_search(tmpl, std::regex("\n#+ [^\n]*(session|[0-9]{4}-[0-9]{2}-[0-9]{2}|hand-written)")))
      << "a heading of the performance template is dated or names a work session";
}
