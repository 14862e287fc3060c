#include "page.h"

#include <sstream>

namespace tega::report {
namespace {

// A table cell must not end its row early.
std::string markdown_cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

void Section::text(std::string paragraph) { blocks.push_back({Block::Kind::text, std::move(paragraph), {}, {}}); }
void Section::table(Table t) { blocks.push_back({Block::Kind::table, {}, std::move(t), {}}); }
void Section::image(std::string path, std::string caption) {
  blocks.push_back({Block::Kind::image, std::move(caption), {}, std::move(path)});
}

std::string page_markdown(const Page& page) {
  std::ostringstream out;
  out << "# " << page.title << "\n";
  for (const auto& section : page.sections) {
    out << "\n## " << section.title << "\n";
    for (const auto& block : section.blocks) {
      out << "\n";
      switch (block.kind) {
        case Block::Kind::text:
          out << block.text << "\n";
          break;
        case Block::Kind::image:
          out << "![" << markdown_cell(block.text) << "](" << block.image << ")\n";
          break;
        case Block::Kind::table: {
          const auto row = [&](const std::vector<std::string>& cells) {
            out << "|";
            for (const auto& cell : cells) out << " " << markdown_cell(cell) << " |";
            out << "\n";
          };
          row(block.table.header);
          out << "|";
          for (size_t i = 0; i < block.table.header.size(); ++i) out << (i ? " ---: |" : " --- |");
          out << "\n";
          for (const auto& cells : block.table.rows) row(cells);
          break;
        }
      }
    }
  }
  return out.str();
}

std::string page_html(const Page& page) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" << html_escape(page.title) << "</title>\n"
      << "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}"
         "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 8px}"
         "td:not(:first-child){text-align:right}img{max-width:100%}figure{margin:1em 0}</style>\n"
      << "</head><body>\n<h1>" << html_escape(page.title) << "</h1>\n";
  for (const auto& section : page.sections) {
    out << "<h2>" << html_escape(section.title) << "</h2>\n";
    for (const auto& block : section.blocks) {
      switch (block.kind) {
        case Block::Kind::text:
          out << "<p>" << html_escape(block.text) << "</p>\n";
          break;
        case Block::Kind::image:
          out << "<figure><img src=\"" << html_escape(block.image) << "\" alt=\"" << html_escape(block.text)
              << "\"><figcaption>" << html_escape(block.text) << "</figcaption></figure>\n";
          break;
        case Block::Kind::table:
          out << "<table><tr>";
          for (const auto& cell : block.table.header) out << "<th>" << html_escape(cell) << "</th>";
          out << "</tr>\n";
          for (const auto& cells : block.table.rows) {
            out << "<tr>";
            for (const auto& cell : cells) out << "<td>" << html_escape(cell) << "</td>";
            out << "</tr>\n";
          }
          out << "</table>\n";
          break;
      }
    }
  }
  out << "</body></html>\n";
  return out.str();
}

}  // namespace tega::report
