// The report's Markdown (report/document.hpp, RenderMarkdown) shows people's text as text.
// Issue 11: report.md copied raw HTML and `javascript:` links from an experiment's notes. Truth:
// the CommonMark specification (0.30): "&lt;" is a character reference, not a tag (§6.6 raw HTML
// needs a literal '<'); a backslash before ASCII punctuation makes it literal (§2.4), so "\[x\]"
// opens no link and "\<" no autolink; a line starting with "\-" or "1\." starts no list (§5.2).
#include <gtest/gtest.h>

#include <string>

#include "report/document.hpp"

namespace uphill::testing {
namespace {

TEST(ReportMarkdown, NotesNeverBecomeHtmlLinksOrBlocks) {
  Document d;
  d.title = "Series <b>2</b>";
  d.Paragraph("<script>alert(1)</script> [click](javascript:alert(1)) <javascript:alert(2)> ![i](x.png) *a* _b_ `c`");
  d.Paragraph("- not a list\n# not a heading");
  d.Paragraph("1. not a list either");
  d.AddTable({{"note"}, {{"a | b"}, {"[x](javascript:y)"}}});
  const std::string md = RenderMarkdown(d);
  for (const char* raw : {"<script", "<b>", "[click]", "<javascript", "![i]", "\n- not", "\n# not", "\n1. not"})
    EXPECT_EQ(md.find(raw), std::string::npos) << raw << " reached the Markdown:\n" << md;
  for (const char* escaped : {"&lt;script&gt;", "\\[click\\]", "&lt;javascript:", "\\*a\\*", "\\_b\\_", "\\`c\\`",
                              "\\- not a list", "1\\. not a list", "a \\| b"})
    EXPECT_NE(md.find(escaped), std::string::npos) << escaped << " missing from:\n" << md;
}

}  // namespace
}  // namespace uphill::testing
