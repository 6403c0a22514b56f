// The parser's field readers (internal to src/opendrive): attribute lookups that fail with
// the file, line and element, shared by parser.cpp and parser_objects.cpp.
#pragma once

#include <tinyxml2.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "opendrive/network.h"

namespace convoy::opendrive::detail {

using tinyxml2::XMLElement;

// Walks the children of `parent` named `name` (all children when name is null).
template <typename F>
void for_each_child(const XMLElement* parent, const char* name, F&& f) {
  if (!parent) return;
  for (const XMLElement* e = parent->FirstChildElement(name); e; e = e->NextSiblingElement(name)) {
    f(e);
  }
}

class XmlFields {
 public:
  explicit XmlFields(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const XMLElement* e, const std::string& where,
                         const std::string& what) const {
    std::string msg = source_;
    if (e) msg += ":" + std::to_string(e->GetLineNum());
    msg += ": ";
    if (!where.empty()) msg += where + ": ";
    throw std::runtime_error(msg + what);
  }

  std::string text(const XMLElement* e, const char* name, const std::string& where) const {
    const char* v = e->Attribute(name);
    if (!v) fail(e, where, std::string("missing attribute '") + name + "'");
    return v;
  }
  std::string text_or(const XMLElement* e, const char* name, const std::string& fallback) const {
    const char* v = e->Attribute(name);
    return v ? v : fallback;
  }
  double number(const XMLElement* e, const char* name, const std::string& where) const {
    return to_number(e, name, text(e, name, where), where);
  }
  double number_or(const XMLElement* e, const char* name, double fallback,
                   const std::string& where) const {
    const char* v = e->Attribute(name);
    return v ? to_number(e, name, v, where) : fallback;
  }
  int integer(const XMLElement* e, const char* name, const std::string& where) const {
    const double v = number(e, name, where);
    if (v != std::floor(v) || std::abs(v) > 1e9) {
      fail(e, where,
           std::string("attribute '") + name + "' must be an integer, got '" +
               text(e, name, where) + "'");
    }
    return static_cast<int>(v);
  }
  double to_number(const XMLElement* e, const char* name, const std::string& value,
                   const std::string& where) const {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(value.c_str(), &end);
    while (end && *end && std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (value.empty() || end == value.c_str() || *end != '\0' || errno == ERANGE ||
        !std::isfinite(v)) {
      fail(e, where, std::string("attribute '") + name + "' is not a number: '" + value + "'");
    }
    return v;
  }
  const std::string& source() const { return source_; }

 protected:
  std::string source_;
};

// <object> (with its outlines and repeats), <signal>, <tunnel> and <bridge> of a road.
RoadObject read_object(const XmlFields& f, const XMLElement* e, const std::string& where);
Signal read_signal(const XmlFields& f, const XMLElement* e, const std::string& where);
RoadSpan read_span(const XmlFields& f, const XMLElement* e, const std::string& where);

}  // namespace convoy::opendrive::detail
