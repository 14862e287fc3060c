# Writes OUT, a C++ source holding the files WEB_FILES (names relative to
# WEB_DIR) as byte arrays for web_assets.h. Run as a script:
#   cmake -DWEB_DIR=... -DWEB_FILES=a,b -DOUT=... -P embed_web.cmake
string(REPLACE "," ";" WEB_FILES "${WEB_FILES}")
set(arrays "")
set(table "")
set(index 0)
foreach(name ${WEB_FILES})
  file(READ ${WEB_DIR}/${name} hex HEX)
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  if(name MATCHES "\\.html$")
    set(type "text/html; charset=utf-8")
  elseif(name MATCHES "\\.js$")
    set(type "text/javascript; charset=utf-8")
  elseif(name MATCHES "\\.css$")
    set(type "text/css; charset=utf-8")
  else()
    set(type "application/octet-stream")
  endif()
  string(APPEND arrays "const unsigned char asset_${index}[] = {${bytes}};\n")
  string(APPEND table "      {\"${name}\", \"${type}\", bytes_of(asset_${index}, sizeof asset_${index})},\n")
  math(EXPR index "${index} + 1")
endforeach()
file(WRITE ${OUT}.tmp "// Generated from serve/web by serve/embed_web.cmake.
#include \"web_assets.h\"

namespace tega::serve {
namespace {
std::string_view bytes_of(const unsigned char* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}
${arrays}}  // namespace

const std::vector<WebAsset>& web_assets() {
  static const std::vector<WebAsset> assets = {
${table}  };
  return assets;
}

}  // namespace tega::serve
")
file(RENAME ${OUT}.tmp ${OUT})
