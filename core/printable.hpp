#pragma once
// Text from outside nelf (file names, profile keys and values, metadata) made safe to print in a
// one-line message: a newline would split the line, and a terminal escape sequence from a shared
// profile or a crafted file name would be executed by the user's terminal.
#include <string>
#include <string_view>

namespace nelf {

// `text` with every byte that is not printable UTF-8 shown as a visible escape: \n, \r, \t as
// such, other C0 controls, DEL and bytes of invalid UTF-8 as \xNN, C1 controls (U+0080..U+009F)
// as \u0080..\u009f. Valid printable UTF-8 (accents, CJK, emoji) and backslashes are kept as they
// are, so that an ordinary message reads unchanged.
std::string printable(std::string_view text);

}  // namespace nelf
