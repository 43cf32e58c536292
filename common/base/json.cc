#include "common/base/json.h"

#include <cmath>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace meshseek {
namespace {

void AppendEscaped(const std::string& s, std::string* out) {
  out->push_back('"');
  for (const char c : s) {
    switch (c) {
      case '"':
        out->append("\\\"");
        break;
      case '\\':
        out->append("\\\\");
        break;
      case '\n':
        out->append("\\n");
        break;
      case '\t':
        out->append("\\t");
        break;
      case '\r':
        out->append("\\r");
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          absl::StrAppendFormat(out, "\\u%04x", static_cast<int>(c));
        } else {
          out->push_back(c);
        }
    }
  }
  out->push_back('"');
}

void Newline(std::string* out, int indent, int depth) {
  if (indent <= 0) return;
  out->push_back('\n');
  out->append(static_cast<std::size_t>(indent * depth), ' ');
}

}  // namespace

Json& Json::Set(const std::string& key, Json value) {
  auto& obj = std::get<Object>(value_);
  for (auto& [k, v] : obj) {
    if (k == key) {
      v = std::move(value);
      return v;
    }
  }
  obj.emplace_back(key, std::move(value));
  return obj.back().second;
}

Json& Json::Push(Json value) {
  auto& arr = std::get<Array>(value_);
  arr.push_back(std::move(value));
  return arr.back();
}

std::string Json::Dump(int indent) const {
  std::string out;
  DumpTo(&out, indent, 0);
  if (indent > 0) out.push_back('\n');
  return out;
}

void Json::DumpTo(std::string* out, int indent, int depth) const {
  if (std::holds_alternative<std::nullptr_t>(value_)) {
    out->append("null");
  } else if (const bool* b = std::get_if<bool>(&value_)) {
    out->append(*b ? "true" : "false");
  } else if (const int64_t* i = std::get_if<int64_t>(&value_)) {
    absl::StrAppend(out, *i);
  } else if (const double* d = std::get_if<double>(&value_)) {
    if (!std::isfinite(*d)) {
      out->append("null");
    } else {
      // %.17g round-trips; trim to a readable form when it is exact.
      std::string s = absl::StrFormat("%.10g", *d);
      if (std::stod(s) != *d) s = absl::StrFormat("%.17g", *d);
      out->append(s);
    }
  } else if (const std::string* s = std::get_if<std::string>(&value_)) {
    AppendEscaped(*s, out);
  } else if (const Object* o = std::get_if<Object>(&value_)) {
    if (o->empty()) {
      out->append("{}");
      return;
    }
    out->push_back('{');
    for (std::size_t k = 0; k < o->size(); ++k) {
      if (k > 0) out->push_back(',');
      Newline(out, indent, depth + 1);
      AppendEscaped((*o)[k].first, out);
      out->append(indent > 0 ? ": " : ":");
      (*o)[k].second.DumpTo(out, indent, depth + 1);
    }
    Newline(out, indent, depth);
    out->push_back('}');
  } else {
    const Array& a = std::get<Array>(value_);
    if (a.empty()) {
      out->append("[]");
      return;
    }
    out->push_back('[');
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (k > 0) out->push_back(',');
      Newline(out, indent, depth + 1);
      a[k].DumpTo(out, indent, depth + 1);
    }
    Newline(out, indent, depth);
    out->push_back(']');
  }
}

}  // namespace meshseek
