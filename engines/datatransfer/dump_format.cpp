#include "dump_format.h"

#include <google/protobuf/text_format.h>

#include <algorithm>
#include <charconv>
#include <cstdio>

#include "nrp_protobuf/engine_grpc.pb.h"

namespace convoy::datatransfer {

namespace gpb = google::protobuf;

std::string seconds_text(int64_t ns) {
  const bool negative = ns < 0;
  const uint64_t a = negative ? 0 - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
  std::string text = (negative ? "-" : "") + std::to_string(a / 1'000'000'000);
  uint64_t frac = a % 1'000'000'000;
  if (frac != 0) {
    char digits[10];
    std::snprintf(digits, sizeof digits, "%09llu", static_cast<unsigned long long>(frac));
    std::string f(digits);
    f.erase(f.find_last_not_of('0') + 1);
    text += "." + f;
  }
  return text;
}

namespace {

template <typename T>
std::string shortest(T value) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);
  return ec == std::errc() ? std::string(buf, end) : std::string("nan");
}

}  // namespace

std::string bytes_text(std::string_view bytes) {
  if (bytes.size() > kMaxBytesInFile) return "<" + std::to_string(bytes.size()) + " bytes>";
  static const char digits[] = "0123456789abcdef";
  std::string out;
  out.reserve(bytes.size() * 2);
  for (unsigned char c : bytes) {
    out += digits[c >> 4];
    out += digits[c & 15];
  }
  return out;
}

namespace {

bool is_dump_string(const gpb::Descriptor& d) {
  return d.full_name() == "Dump.String" && d.FindFieldByName("string_stream") != nullptr;
}

bool is_dump_array_float(const gpb::Descriptor& d) {
  const gpb::FieldDescriptor* values = d.FindFieldByName("float_stream");
  const gpb::FieldDescriptor* dims = d.FindFieldByName("dims");
  return d.full_name() == "Dump.ArrayFloat" && values && values->is_repeated() &&
         values->cpp_type() == gpb::FieldDescriptor::CPPTYPE_FLOAT && dims && dims->is_repeated();
}

// protobuf's one-line text form, long strings and bytes cut at kMaxBytesInFile.
std::string short_text(const gpb::Message& m) {
  gpb::TextFormat::Printer printer;
  printer.SetSingleLineMode(true);
  printer.SetTruncateStringFieldLongerThan(kMaxBytesInFile);
  std::string out;
  printer.PrintToString(m, &out);
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// One element of a field (index < 0: a singular field).
std::string value_text(const gpb::Message& m, const gpb::FieldDescriptor* f, int index) {
  const gpb::Reflection* r = m.GetReflection();
  const bool rep = index >= 0;
  switch (f->cpp_type()) {
    case gpb::FieldDescriptor::CPPTYPE_INT32:
      return std::to_string(rep ? r->GetRepeatedInt32(m, f, index) : r->GetInt32(m, f));
    case gpb::FieldDescriptor::CPPTYPE_INT64:
      return std::to_string(rep ? r->GetRepeatedInt64(m, f, index) : r->GetInt64(m, f));
    case gpb::FieldDescriptor::CPPTYPE_UINT32:
      return std::to_string(rep ? r->GetRepeatedUInt32(m, f, index) : r->GetUInt32(m, f));
    case gpb::FieldDescriptor::CPPTYPE_UINT64:
      return std::to_string(rep ? r->GetRepeatedUInt64(m, f, index) : r->GetUInt64(m, f));
    case gpb::FieldDescriptor::CPPTYPE_DOUBLE:
      return shortest(rep ? r->GetRepeatedDouble(m, f, index) : r->GetDouble(m, f));
    case gpb::FieldDescriptor::CPPTYPE_FLOAT:
      return shortest(rep ? r->GetRepeatedFloat(m, f, index) : r->GetFloat(m, f));
    case gpb::FieldDescriptor::CPPTYPE_BOOL:
      return (rep ? r->GetRepeatedBool(m, f, index) : r->GetBool(m, f)) ? "1" : "0";
    case gpb::FieldDescriptor::CPPTYPE_ENUM:
      return std::to_string(rep ? r->GetRepeatedEnumValue(m, f, index) : r->GetEnumValue(m, f));
    case gpb::FieldDescriptor::CPPTYPE_STRING: {
      std::string s = rep ? r->GetRepeatedString(m, f, index) : r->GetString(m, f);
      return f->type() == gpb::FieldDescriptor::TYPE_BYTES ? bytes_text(s) : s;
    }
    case gpb::FieldDescriptor::CPPTYPE_MESSAGE: {
      const gpb::Message& sub = rep ? r->GetRepeatedMessage(m, f, index) : r->GetMessage(m, f);
      return "{" + short_text(sub) + "}";
    }
  }
  return "";
}

std::string field_text(const gpb::Message& m, const gpb::FieldDescriptor* f) {
  if (!f->is_repeated()) return value_text(m, f, -1);
  std::string out = "[";
  const int n = m.GetReflection()->FieldSize(m, f);
  for (int i = 0; i < n; ++i) {
    if (i) out += ' ';
    out += value_text(m, f, i);
  }
  return out + "]";
}

}  // namespace

std::string number_text(double value) { return shortest(value); }
std::string number_text(float value) { return shortest(value); }

std::string csv_cell(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string proto_header(const gpb::Descriptor& type) {
  if (is_dump_string(type) || is_dump_array_float(type)) return "";
  std::string line = "sim_time";
  for (int i = 0; i < type.field_count(); ++i) line += "," + csv_cell(type.field(i)->name());
  return line;
}

std::string proto_line(const gpb::Message& message, int64_t time_ns) {
  const gpb::Descriptor& type = *message.GetDescriptor();
  const gpb::Reflection* r = message.GetReflection();
  std::string line = seconds_text(time_ns);
  if (is_dump_string(type)) {
    return line + "," + r->GetString(message, type.FindFieldByName("string_stream"));
  }
  if (is_dump_array_float(type)) {
    const gpb::FieldDescriptor* values = type.FindFieldByName("float_stream");
    const gpb::FieldDescriptor* dims = type.FindFieldByName("dims");
    const int n = r->FieldSize(message, values);
    if (r->FieldSize(message, dims) != 2) {
      line += ",0";
      for (int i = 0; i < n; ++i) line += "," + value_text(message, values, i);
      return line;
    }
    line += ",";
    // Rows beyond the values are printed empty, as NRP-Core does, but not without bound.
    const int64_t rows = std::min<int64_t>(std::stoll(value_text(message, dims, 0)), n + 1024);
    const int64_t cols = std::stoll(value_text(message, dims, 1));
    for (int64_t row = 0, i = 0; row < rows; ++row) {
      line += "\n" + std::to_string(row);
      for (int64_t col = 0; col < cols && i < n; ++col, ++i) {
        line += "," + value_text(message, values, static_cast<int>(i));
      }
    }
    return line;
  }
  for (int i = 0; i < type.field_count(); ++i) {
    line += "," + csv_cell(field_text(message, type.field(i)));
  }
  return line;
}

std::string json_line(const nlohmann::json& value, int64_t time_ns) {
  return seconds_text(time_ns) + "," +
         value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string datapack_message(std::string_view name, std::string_view engine_name,
                             std::string_view type_name, std::string_view data) {
  EngineGrpc::DataPackMessage message;
  auto* id = message.mutable_datapackid();
  id->set_datapackname(std::string(name));
  id->set_datapacktype(std::string(type_name));
  id->set_enginename(std::string(engine_name));
  // What Any::PackFrom writes, without parsing the message again.
  message.mutable_data()->set_type_url("type.googleapis.com/" + std::string(type_name));
  message.mutable_data()->set_value(std::string(data));
  return message.SerializeAsString();
}

nlohmann::json json_datapack_message(std::string_view name, std::string_view engine_name,
                                     const nlohmann::json& value) {
  return {{"datapackId",
           {{"dataPackName", name}, {"engineName", engine_name}, {"dataPackType", "json"}}},
          {"data", value}};
}

}  // namespace convoy::datatransfer
