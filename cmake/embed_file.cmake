# Writes OUTPUT, a C++ file defining nusselt::kDefaultSceneBytes with the bytes of INPUT.
file(READ ${INPUT} hex HEX)
string(LENGTH "${hex}" n)
math(EXPR bytes "${n} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," body "${hex}")
string(REGEX REPLACE "((0x..,){32})" "\\1\n" body "${body}")
file(WRITE ${OUTPUT} "// Generated from ${INPUT} by cmake/embed_file.cmake.\n#include <cstddef>\nnamespace nusselt {\nextern const unsigned char kDefaultSceneBytes[];\nextern const std::size_t kDefaultSceneSize;\nconst unsigned char kDefaultSceneBytes[] = {\n${body}\n};\nconst std::size_t kDefaultSceneSize = ${bytes};\n}\n")
