// Document: a report as a list of blocks (headings, paragraphs, tables, figures), rendered to a
// self-contained HTML page or to Markdown from the same content, so the two never drift apart.
//
// HTML: one file that opens offline — inline CSS, figures embedded as base64 SVG data URIs, every
// piece of user text (notes, labels) escaped, no scripts. Markdown: figures linked by file name
// (the PNGs beside it), table cells with '|' escaped.
#pragma once

#include <string>
#include <vector>

namespace uphill {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Block {
  enum class Kind { kHeading, kParagraph, kList, kTable, kFigure } kind = Kind::kParagraph;
  std::string text;                 // heading, paragraph; figure title
  std::vector<std::string> items;   // list items
  Table table;
  std::string figure_stem;          // figure: NAME (NAME.svg and NAME.png beside the document)
  std::string caption;              // figure caption
};

struct Document {
  std::string title;
  std::vector<Block> blocks;

  void Heading(const std::string& text);
  void Paragraph(const std::string& text);
  void List(const std::vector<std::string>& items);
  void AddTable(const Table& table);
  void Figure(const std::string& stem, const std::string& title, const std::string& caption);
};

std::string HtmlEscape(const std::string& text);
std::string Base64(const std::string& bytes);

// `directory` is where the figures' SVG files are (read to embed them).
std::string RenderHtml(const Document& document, const std::string& directory);
std::string RenderMarkdown(const Document& document);

}  // namespace uphill
