# Writes the page's bundled script (IN) as a C++ source (OUT) defining spx::kPageBundle and
# kPageBundleSize; IN empty or missing: an empty bundle (proxy-export then refuses .html).
# cmake -DIN=page.js -DOUT=page_bundle.cpp -P embed_page.cmake
set(size 0)
set(body "0")
if(EXISTS "${IN}")
  file(READ "${IN}" text)
  string(FIND "${text}" "</script" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "${IN} holds \"</script\": it cannot go inside a <script> element")
  endif()
  file(SIZE "${IN}" size)
  file(READ "${IN}" hex HEX)
  string(REGEX REPLACE "(..)" "0x\\1," body "${hex}")
  string(REGEX REPLACE "((0x..,){32})" "\\1\n" body "${body}")
endif()
file(WRITE "${OUT}.tmp" "// Generated from web/page by cmake/embed_page.cmake: do not edit.\n#include <cstddef>\n"
  "namespace spx {\nextern const char kPageBundle[];\nextern const size_t kPageBundleSize;\n"
  "const char kPageBundle[] = {\n${body}};\nconst size_t kPageBundleSize = ${size};\n}  // namespace spx\n")
file(RENAME "${OUT}.tmp" "${OUT}")
