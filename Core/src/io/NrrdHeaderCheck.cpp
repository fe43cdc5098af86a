#include "NrrdHeaderCheck.h"

#include "repose/util/Error.h"

#include <teem/nrrd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <optional>

namespace repose::io {
namespace {

// teem formats a field's text into a fixed-size stack buffer when it cannot parse it: a value of
// ~1,000-1,900 characters smashed its stack. Real field lines are a few hundred characters at most
// (sizes, space directions of a 3D volume); key:=value pairs and comments are stored, not parsed,
// and may be long (Slicer's segment tags).
constexpr std::size_t kMaxFieldLine = 800;
constexpr const char* kFieldSep = " \t";  // teem's _nrrdFieldSep

// A non-negative count as teem's "%u" reads it; nothing when it is not one.
std::optional<unsigned> parseCount(const std::string& text) {
  const std::size_t start = text.find_first_not_of(kFieldSep);
  if (start == std::string::npos || text[start] < '0' || text[start] > '9') return std::nullopt;
  char* end = nullptr;
  const unsigned long v = std::strtoul(text.c_str() + start, &end, 10);
  if (v > 64) return std::nullopt;  // teem's NRRD_DIM_MAX is 16: either way teem refuses it
  return unsigned(v);
}

// How many closed quoted strings `text` holds, read as teem reads labels and units (whitespace,
// then "...", with \" inside), when it holds nothing else; nothing otherwise.
std::optional<unsigned> quotedStrings(const std::string& text) {
  unsigned n = 0;
  std::size_t i = 0;
  for (;;) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    if (i == text.size()) return n;
    if (text[i] != '"') return std::nullopt;
    for (++i; i < text.size() && text[i] != '"'; ++i)
      if (text[i] == '\\' && i + 1 < text.size() && text[i + 1] == '"') ++i;
    if (i == text.size()) return std::nullopt;  // not closed
    ++i, ++n;
  }
}

class HeaderCheck {
 public:
  explicit HeaderCheck(const std::string& path) : path_(path) {}

  void line(std::size_t n, const std::string& text) {
    if (text.find('\0') != std::string::npos)
      fail(n, "holds a NUL byte: not a NRRD header (corrupt file)");
    if (n == 1) {
      const bool magic = text.size() == 8 && text.compare(0, 7, "NRRD000") == 0 && text[7] >= '1' &&
                         text[7] <= '5';
      if (!magic)
        throwFileError(path_, "not a NRRD file: the first line is not NRRD0001 to NRRD0005");
      return;
    }
    if (text[0] == '#') return;
    // A key:=value pair when the first ':' is followed by '=' ("a:b ... :=c" is a field to teem,
    // and an unparseable one).
    const std::size_t colon = text.find(':');
    if (colon != std::string::npos && colon + 1 < text.size() && text[colon + 1] == '=') return;
    if (text.size() > kMaxFieldLine)
      throwFileError(path_, "header line " + std::to_string(n) + " (" +
                                text.substr(0, std::min<std::size_t>(colon, 40)) + ") is " +
                                std::to_string(text.size()) +
                                " characters long: not a NRRD field (corrupt header)");
    // teem's field name: the text before the first ": ".
    const std::size_t sep = text.find(": ");
    if (sep == std::string::npos) return;
    const std::string name = text.substr(0, sep);
    const int field = airEnumVal(nrrdField, name.c_str());
    std::string value = text.substr(sep + 2);
    value.erase(0, std::min(value.size(), value.find_first_not_of(kFieldSep)));
    field_(n, name, field, value);
  }

 private:
  void field_(std::size_t n, const std::string& name, int field, const std::string& value) {
    switch (field) {
      case nrrdField_dimension:
        dimensionSeen_ = true;
        dimension_ = parseCount(value);
        return;
      case nrrdField_space:
        spaceSeen_ = true;
        spaceDimension_ = std::nullopt;
        if (const int space = airEnumVal(nrrdSpace, value.c_str()))
          spaceDimension_ = nrrdSpaceDimension(space);
        return;
      case nrrdField_space_dimension:
        spaceSeen_ = true;
        spaceDimension_ = parseCount(value);
        return;
      case nrrdField_data_file:
        // A list or a numbered template needs the dimension; a single file name does not.
        if (value.find('%') != std::string::npos || value.rfind("LIST", 0) == 0 ||
            value.rfind("SKIPLIST", 0) == 0)
          needDimension(n, name);
        return;
      case nrrdField_space_directions:
        needDimension(n, name);
        needSpace(n, name);
        return;
      case nrrdField_space_origin:
      case nrrdField_measurement_frame:
        needSpace(n, name);
        return;
      case nrrdField_space_units:
        needSpace(n, name);
        needQuoted(n, name, value, spaceDimension_, "space axis");
        return;
      case nrrdField_labels:
      case nrrdField_units:
        needDimension(n, name);
        needQuoted(n, name, value, dimension_, "axis");
        return;
      default:
        if (field >= nrrdField_sizes && field <= nrrdField_units) needDimension(n, name);
        return;
    }
  }

  void needDimension(std::size_t n, const std::string& name) const {
    if (!dimensionSeen_)
      fail(n, "(" + name + ") comes before the dimension field, which NRRD needs first (corrupt " +
                  "header)");
  }
  void needSpace(std::size_t n, const std::string& name) const {
    if (!spaceSeen_)
      fail(n, "(" + name + ") comes before the space or space dimension field, which NRRD " +
                  "needs first (corrupt header)");
  }
  // Exactly `count` closed quoted strings, when the count is known (an unparseable dimension is
  // refused by teem on its own line, before this one).
  void needQuoted(std::size_t n, const std::string& name, const std::string& value,
                  std::optional<unsigned> count, const char* per) const {
    const std::optional<unsigned> got = quotedStrings(value);
    if (!got) fail(n, "(" + name + ") is not a list of closed quoted strings (corrupt header)");
    if (count && *got != *count)
      fail(n, "(" + name + ") holds " + std::to_string(*got) + " quoted strings, not one per " +
                  per + " (" + std::to_string(*count) + ") (corrupt header)");
  }

  [[noreturn]] void fail(std::size_t n, const std::string& problem) const {
    throwFileError(path_, "header line " + std::to_string(n) + " " + problem);
  }

  const std::string& path_;
  bool dimensionSeen_ = false;
  bool spaceSeen_ = false;
  std::optional<unsigned> dimension_;
  std::optional<unsigned> spaceDimension_;
};

}  // namespace

void checkNrrdHeader(const std::string& path) {
  // Lines split as teem splits them: a line ends at "\n", "\r" or "\r\n" (a lone "\r" inside a
  // long key:=value line made its tail a field line to teem). An attached header ends at its
  // first empty line; a detached one at the end of the file.
  std::ifstream in(path, std::ios::binary);
  HeaderCheck check(path);
  std::string line;
  std::size_t n = 1;
  for (int c = in.get(); c != std::char_traits<char>::eof(); c = in.get()) {
    if (c != '\n' && c != '\r') {
      line.push_back(char(c));
      continue;
    }
    if (c == '\r' && in.peek() == '\n') in.get();
    if (line.empty() && n > 1) return;
    check.line(n++, line);
    line.clear();
  }
  if (!line.empty() || n == 1) check.line(n, line);
}

}  // namespace repose::io
