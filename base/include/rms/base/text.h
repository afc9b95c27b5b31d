#pragma once
// printf-style formatting into a std::string, for status screens and
// monitors (lines of fixed columns).
#include <cstdarg>
#include <cstdio>
#include <string>
#include <string_view>

#include "rms/base/folder_file.h"

namespace rms {

std::string Sprintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

// A number as people write it (docs/sessions.md "Command lines"): at most
// `decimals` decimals, trailing zeros dropped ("20.9", not
// "20.899999999999999"; "3", not "3.000"); two significant digits below
// 10^-decimals; "nan" and "inf" as such.
std::string HumanNumber(double v, int decimals = 3);

// Writes `text` as the whole of the file at `path`; throws rms::InputError
// naming the file and why when any of it could not be written: a tool must
// not end as if its output were there. A file is written to a fresh
// temporary file beside it and renamed over its name, so a failure leaves
// no part of it, and a link planted at its name is replaced, never written
// through (rms/base/folder_file.h). Anything under /dev or /proc is
// written directly. links: Links::kFollow for a path the user named on
// the command line outside a session's folder (LinksForOutput): a link, a
// FIFO or a device there is written directly, as the user meant (`--out
// /dev/stdout`), a FIFO nothing reads refused; Links::kRefuse (a name in a
// session's folder) replaces a link, FIFO or device node planted there.
void WriteWholeFile(const std::string& path, const std::string& text, Links links = Links::kRefuse);

// Escaping for the context a string from a message or a session folder
// lands in (docs/security.md "Text from messages and folders"); each tested
// with `<!--<script>`, quotes, control characters and invalid UTF-8.
//
// HTML text or a quoted attribute's value: & < > " ' as entities.
std::string HtmlText(std::string_view s);
// One CSV field (RFC 4180): in quotes, quotes doubled, when it holds a
// comma, a quote, CR or LF; a text beginning = + - @ TAB or CR that is not
// a number gets a leading ' (a spreadsheet then takes it as text, not as a
// formula).
std::string CsvField(std::string_view s);
// Text to print on a terminal: every control character (C0 but LF and TAB,
// and DEL, as \xNN; C1, U+0080..U+009F in UTF-8, as \u00NN), so a forged
// name cannot clear the screen, set the window's title or move the cursor.
std::string TerminalText(std::string_view s);

}  // namespace rms
