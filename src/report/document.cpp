#include "report/document.hpp"

#include <boost/archive/iterators/base64_from_binary.hpp>
#include <boost/archive/iterators/transform_width.hpp>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

const char* kCss = R"(body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.7em;border-bottom:2px solid #1f4e79;padding-bottom:.2em}h2{font-size:1.3em;color:#1f4e79;margin-top:1.6em}
table{border-collapse:collapse;margin:.6em 0 1.2em;font-size:.88em}th,td{border:1px solid #ccc;padding:.25em .55em;text-align:right;vertical-align:top}
th{background:#eef3f8}td.n{white-space:nowrap}td.t,th:first-child{text-align:left}tr:nth-child(even) td{background:#fafafa}
figure{margin:1em 0 1.6em}figure img{width:100%;max-width:900px;border:1px solid #ddd}figcaption{font-size:.9em;color:#555;max-width:900px}
.note{color:#555;font-size:.9em})";

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw EnvironmentError(path + ": cannot be read to embed it in the report");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Numbers (and "-") are right-aligned and never wrapped; text is left-aligned and wraps.
bool LooksNumeric(const std::string& s) {
  if (s.empty() || s == "-") return true;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0';
}

// Text as Markdown shows it, never as markup: the report's text is plain (notes, titles, labels
// typed by people), so nothing in it may become HTML, a link (`[x](javascript:…)`, `<javascript:…>`),
// an image, emphasis or a heading. HTML's special characters become entities; Markdown's are
// escaped with a backslash (CommonMark: any ASCII punctuation may be); line breaks become spaces,
// so a typed line can never start a block of its own.
std::string MarkdownText(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '\\': case '`': case '*': case '_': case '[': case ']': case '|': case '#': case '~':
        out += '\\';
        out += c;
        break;
      case '\n': case '\r': out += ' '; break;
      default: out += c;
    }
  }
  // A block that starts like a list item or a setext underline stays a paragraph.
  const std::size_t first = out.find_first_not_of(' ');
  if (first != std::string::npos) {
    const char c = out[first];
    std::size_t digits = first;
    while (digits < out.size() && std::isdigit(static_cast<unsigned char>(out[digits]))) ++digits;
    if (c == '-' || c == '+' || c == '=') out.insert(first, 1, '\\');
    else if (digits > first && digits < out.size() && (out[digits] == '.' || out[digits] == ')')) out.insert(digits, 1, '\\');
  }
  return out;
}

// A table cell: its text, one line (a line break is the cell's own <br>).
std::string MarkdownCell(const std::string& s) {
  std::string out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t newline = s.find('\n', start);
    out += MarkdownText(s.substr(start, newline == std::string::npos ? std::string::npos : newline - start));
    if (newline == std::string::npos) break;
    out += "<br>";
    start = newline + 1;
  }
  return out;
}

}  // namespace

void Document::Heading(const std::string& text) { blocks.push_back({Block::Kind::kHeading, text, {}, {}, "", ""}); }
void Document::Paragraph(const std::string& text) { blocks.push_back({Block::Kind::kParagraph, text, {}, {}, "", ""}); }
void Document::List(const std::vector<std::string>& items) {
  if (!items.empty()) blocks.push_back({Block::Kind::kList, "", items, {}, "", ""});
}
void Document::AddTable(const Table& table) { blocks.push_back({Block::Kind::kTable, "", {}, table, "", ""}); }
void Document::Figure(const std::string& stem, const std::string& title, const std::string& caption) {
  blocks.push_back({Block::Kind::kFigure, title, {}, {}, stem, caption});
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Base64(const std::string& bytes) {
  using namespace boost::archive::iterators;
  using Encoder = base64_from_binary<transform_width<std::string::const_iterator, 6, 8>>;
  std::string out(Encoder(bytes.begin()), Encoder(bytes.end()));
  out.append((3 - bytes.size() % 3) % 3, '=');
  return out;
}

std::string RenderHtml(const Document& d, const std::string& directory) {
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << HtmlEscape(d.title)
    << "</title>\n<style>\n" << kCss << "\n</style>\n</head>\n<body>\n<h1>" << HtmlEscape(d.title) << "</h1>\n";
  for (const Block& b : d.blocks) {
    switch (b.kind) {
      case Block::Kind::kHeading: o << "<h2>" << HtmlEscape(b.text) << "</h2>\n"; break;
      case Block::Kind::kParagraph: o << "<p>" << HtmlEscape(b.text) << "</p>\n"; break;
      case Block::Kind::kList:
        o << "<ul>\n";
        for (const auto& item : b.items) o << "<li>" << HtmlEscape(item) << "</li>\n";
        o << "</ul>\n";
        break;
      case Block::Kind::kTable:
        o << "<table>\n<tr>";
        for (const auto& h : b.table.header) o << "<th>" << HtmlEscape(h) << "</th>";
        o << "</tr>\n";
        for (const auto& row : b.table.rows) {
          o << "<tr>";
          for (const auto& cell : row)
            o << "<td class=\"" << (LooksNumeric(cell) ? "n" : "t") << "\">" << HtmlEscape(cell) << "</td>";
          o << "</tr>\n";
        }
        o << "</table>\n";
        break;
      case Block::Kind::kFigure: {
        const std::string svg = Slurp((std::filesystem::path(directory) / (b.figure_stem + ".svg")).string());
        o << "<figure>\n<img alt=\"" << HtmlEscape(b.text) << "\" src=\"data:image/svg+xml;base64," << Base64(svg)
          << "\">\n<figcaption><b>" << HtmlEscape(b.text) << ".</b> " << HtmlEscape(b.caption) << " (files: "
          << HtmlEscape(b.figure_stem) << ".svg, .png, .gp, .dat)</figcaption>\n</figure>\n";
        break;
      }
    }
  }
  o << "</body>\n</html>\n";
  return o.str();
}

std::string RenderMarkdown(const Document& d) {
  std::ostringstream o;
  o << "# " << MarkdownText(d.title) << "\n\n";
  for (const Block& b : d.blocks) {
    switch (b.kind) {
      case Block::Kind::kHeading: o << "## " << MarkdownText(b.text) << "\n\n"; break;
      case Block::Kind::kParagraph: o << MarkdownText(b.text) << "\n\n"; break;
      case Block::Kind::kList:
        for (const auto& item : b.items) o << "- " << MarkdownText(item) << "\n";
        o << "\n";
        break;
      case Block::Kind::kTable:
        o << "|";
        for (const auto& h : b.table.header) o << " " << MarkdownCell(h) << " |";
        o << "\n|";
        for (size_t i = 0; i < b.table.header.size(); ++i) o << (i == 0 ? "---|" : "---:|");
        o << "\n";
        for (const auto& row : b.table.rows) {
          o << "|";
          for (const auto& cell : row) o << " " << MarkdownCell(cell) << " |";
          o << "\n";
        }
        o << "\n";
        break;
      case Block::Kind::kFigure:
        o << "![" << MarkdownText(b.text) << "](" << b.figure_stem << ".png)\n\n*" << MarkdownText(b.text) << ".* "
          << MarkdownText(b.caption) << " (`" << b.figure_stem << ".svg`, script `" << b.figure_stem << ".gp`)\n\n";
        break;
    }
  }
  return o.str();
}

}  // namespace uphill
