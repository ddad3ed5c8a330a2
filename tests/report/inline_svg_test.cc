// gnuplot's SVG documents inside a page: the <svg> element alone, ids prefixed and the
// references to them rewritten (so that figures do not share ids), the files taken.
#include "plumb/report/inline_svg.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "plumb/core/error.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// What gnuplot 5.4's svg terminal writes, cut down: prolog, title, defs with ids, uses of
/// them in both quote styles, a filter by url(), colours that look like references.
const char kDocument[] =
    "<?xml version=\"1.0\" encoding=\"utf-8\"  standalone=\"no\"?>\n"
    "<!DOCTYPE svg PUBLIC \"-//W3C//DTD SVG 1.1//EN\" \"http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd\">\n"
    "<svg \n width=\"600\" height=\"400\"\n viewBox=\"0 0 600 400\"\n"
    " xmlns=\"http://www.w3.org/2000/svg\"\n xmlns:xlink=\"http://www.w3.org/1999/xlink\"\n>\n\n"
    "<title>Gnuplot</title>\n<desc>Produced by GNUPLOT 5.4 patchlevel 4 </desc>\n"
    "<g id=\"gnuplot_canvas\">\n<defs>\n"
    "\t<circle id='gpDot' r='0.5'/>\n"
    "\t<path id='gpPt7' d='M0,-1.33 L-1.33,0.67 z'/>\n"
    "\t<use xlink:href='#gpPt7' id='gpPt8' fill='currentColor'/>\n"
    "\t<filter id='textbox' x='0' y='0'/>\n</defs>\n"
    "<g color=\"#FFFFFF\" stroke=\"currentColor\"><rect fill=\"#ffffff\"/></g>\n"
    "<use href=\"#gpPt8\" transform='translate(45.50,50.35)'/>\n"
    "<g filter='url(#textbox)'><text>xid='a'</text></g>\n"
    "<a xlink:href='#elsewhere'>x</a>\n"
    "</g>\n</svg>\n\n";

TEST(InlineSvg, KeepsTheSvgElementAndPrefixesEveryIdAndReference) {
  const std::string svg = InlineSvg(kDocument, "series-");
  EXPECT_EQ(svg.rfind("<svg \n width=\"600\"", 0), 0u) << svg;  // no prolog, no DOCTYPE
  EXPECT_EQ(svg.substr(svg.size() - 6), "</svg>");
  EXPECT_FALSE(Contains(svg, "<title>"));  // gnuplot's, a misleading tooltip
  EXPECT_TRUE(Contains(svg, "<desc>Produced by GNUPLOT"));
  for (const char* part :
       {"<g id=\"series-gnuplot_canvas\">", "<circle id='series-gpDot'", "<path id='series-gpPt7'",
        "<use xlink:href='#series-gpPt7' id='series-gpPt8'", "<filter id='series-textbox'",
        "<use href=\"#series-gpPt8\"", "filter='url(#series-textbox)'"}) {
    EXPECT_TRUE(Contains(svg, part)) << part << "\n" << svg;
  }
  // Colours, text and references to ids the document does not define are left alone.
  EXPECT_TRUE(Contains(svg, "color=\"#FFFFFF\""));
  EXPECT_TRUE(Contains(svg, "fill=\"#ffffff\""));
  EXPECT_TRUE(Contains(svg, "<text>xid='a'</text>"));
  EXPECT_TRUE(Contains(svg, "xlink:href='#elsewhere'"));
  EXPECT_FALSE(Contains(svg, "'#gpPt"));
  EXPECT_FALSE(Contains(svg, "id='gp"));
}

TEST(InlineSvg, AnEmptyPrefixChangesNoId) {
  const std::string svg = InlineSvg(kDocument, "");
  EXPECT_TRUE(Contains(svg, "<use xlink:href='#gpPt7' id='gpPt8'"));
}

TEST(InlineSvg, RefusesWhatIsNotAnSvgDocumentAndABadPrefix) {
  EXPECT_THROW(InlineSvg("<html><body>no figure</body></html>", "a-", "x.svg"), Error);
  EXPECT_THROW(InlineSvg("<svgfoo></svgfoo>", "a-"), Error);
  EXPECT_THROW(InlineSvg(kDocument, "a\"b"), Error);
  try {
    InlineSvg("", "a-", "figures/x.svg");
    FAIL();
  } catch (const Error& e) {
    EXPECT_TRUE(Contains(e.what(), "figures/x.svg")) << e.what();
  }
}

TEST(TakeSvgFiles, ReadsEachFileWithItsOwnPrefixAndRemovesIt) {
  testing::TempDir dir;
  for (const char* name : {"series.svg", "noise.svg"}) std::ofstream(dir.File(name)) << kDocument;
  const std::vector<InlineFigure> figures =
      TakeSvgFiles(dir.path().string(), {"series.svg", "noise.svg"});
  ASSERT_EQ(figures.size(), 2u);
  EXPECT_EQ(figures[0].file, "series.svg");
  EXPECT_TRUE(Contains(figures[0].svg, "id='series-gpPt7'"));
  EXPECT_TRUE(Contains(figures[1].svg, "id='noise-gpPt7'"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("series.svg")));
  EXPECT_FALSE(std::filesystem::exists(dir.File("noise.svg")));
  EXPECT_THROW(TakeSvgFiles(dir.path().string(), {"series.svg"}), Error);  // gone
}

}  // namespace
}  // namespace plumb::report
