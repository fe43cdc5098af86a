// A small tolerant reader for the Caret LabelTable XML: only <Label> elements matter, so a full
// XML parser is not worth the dependency; unknown elements and attributes are ignored.
#include "NiftiLabelExtension.h"

#include "repose/util/XmlText.h"

#include <cstdlib>
#include <sstream>

namespace repose::nifti {
namespace {

std::string unescapeXml(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      out += s[i];
      continue;
    }
    const std::size_t semi = s.find(';', i);
    if (semi == std::string::npos) {
      out += s[i];
      continue;
    }
    const std::string entity = s.substr(i + 1, semi - i - 1);
    if (entity == "amp")
      out += '&';
    else if (entity == "lt")
      out += '<';
    else if (entity == "gt")
      out += '>';
    else if (entity == "quot")
      out += '"';
    else if (entity == "apos")
      out += '\'';
    else if (!entity.empty() && entity[0] == '#') {
      const long code = entity.size() > 1 && entity[1] == 'x'
                            ? std::strtol(entity.c_str() + 2, nullptr, 16)
                            : std::strtol(entity.c_str() + 1, nullptr, 10);
      out += code > 0 && code < 128 ? static_cast<char>(code) : '?';
    } else {
      out += s.substr(i, semi - i + 1);
    }
    i = semi;
  }
  return out;
}

// Value of attribute `name` in the text of one start tag, or empty.
std::string attribute(const std::string& tag, const std::string& name) {
  std::size_t pos = 0;
  while ((pos = tag.find(name, pos)) != std::string::npos) {
    const bool boundary = pos > 0 && (tag[pos - 1] == ' ' || tag[pos - 1] == '\t' ||
                                      tag[pos - 1] == '\n' || tag[pos - 1] == '\r');
    std::size_t eq = pos + name.size();
    while (eq < tag.size() && tag[eq] == ' ') ++eq;
    if (boundary && eq < tag.size() && tag[eq] == '=') {
      std::size_t q = eq + 1;
      while (q < tag.size() && tag[q] == ' ') ++q;
      if (q < tag.size() && (tag[q] == '"' || tag[q] == '\'')) {
        const std::size_t end = tag.find(tag[q], q + 1);
        if (end != std::string::npos) return unescapeXml(tag.substr(q + 1, end - q - 1));
      }
    }
    pos += name.size();
  }
  return "";
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

}  // namespace

LabelTable parseCaretLabelTable(const std::string& xml) {
  LabelTable table;
  std::size_t pos = 0;
  while ((pos = xml.find("<Label", pos)) != std::string::npos) {
    const char next = pos + 6 < xml.size() ? xml[pos + 6] : '\0';
    if (next != ' ' && next != '\t' && next != '\n' && next != '>') {  // <LabelTable> etc.
      pos += 6;
      continue;
    }
    const std::size_t tagEnd = xml.find('>', pos);
    if (tagEnd == std::string::npos) break;
    const std::string tag = xml.substr(pos, tagEnd - pos);
    const std::size_t close = xml.find("</Label>", tagEnd);
    if (close == std::string::npos) break;
    std::string text = xml.substr(tagEnd + 1, close - tagEnd - 1);
    pos = close + 8;
    const std::string key = attribute(tag, "Key");
    if (key.empty()) continue;
    Label label;
    label.value = std::atoi(key.c_str());
    if (label.value == 0) continue;
    const std::size_t cdata = text.find("<![CDATA[");
    if (cdata != std::string::npos) {
      const std::size_t end = text.find("]]>", cdata);
      text = text.substr(cdata + 9, end == std::string::npos ? std::string::npos : end - cdata - 9);
    } else {
      text = unescapeXml(text);
    }
    label.name = trim(text);
    const std::string r = attribute(tag, "Red"), g = attribute(tag, "Green"),
                      b = attribute(tag, "Blue");
    if (!r.empty() && !g.empty() && !b.empty())
      label.color = {std::atof(r.c_str()), std::atof(g.c_str()), std::atof(b.c_str())};
    else {
      label.color = LabelTable::defaultColor(label.value, label.name);
      label.colorGenerated = true;
    }
    table.set(label);
  }
  return table;
}

std::string formatCaretLabelTable(const LabelTable& labels) {
  std::ostringstream out;
  out.precision(9);
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<CaretExtension>\n"
         "  <VolumeInformation Index=\"0\">\n   <LabelTable>\n";
  for (const Label& l : labels.labels()) {
    if (l.layer != 0 || l.value == 0) continue;
    out << "<Label Key=\"" << l.value << "\" Red=\"" << l.color[0] << "\" Green=\"" << l.color[1]
        << "\" Blue=\"" << l.color[2] << "\" Alpha=\"1\">" << escapeXml(l.name) << "</Label>\n";
  }
  out << "   </LabelTable>\n  </VolumeInformation>\n</CaretExtension>\n";
  return out.str();
}

}  // namespace repose::nifti
