#pragma once
// The report page as data: sections of paragraphs, tables and images, written
// out once as Markdown and once as HTML so that the two always agree.

#include <string>
#include <vector>

namespace tega::report {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Block {
  enum class Kind { text, table, image };
  Kind kind = Kind::text;
  std::string text;  // text: a paragraph; image: its caption
  Table table;
  std::string image;  // image: a path relative to the page
};

struct Section {
  std::string title;
  std::vector<Block> blocks;

  void text(std::string paragraph);
  void table(Table table);
  void image(std::string path, std::string caption);
};

struct Page {
  std::string title;
  std::vector<Section> sections;
};

std::string page_markdown(const Page& page);
std::string page_html(const Page& page);  // a standalone page, no scripts or external styles

}  // namespace tega::report
