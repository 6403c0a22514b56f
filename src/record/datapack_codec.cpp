#include "record/datapack_codec.h"

#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "convoy/datapacks.pb.h"
#include "datapack/camera.h"
#include "datapack/datapack.h"
#include "datapack/json.h"
#include "datapack/ndarray.h"
#include "datapack/proto.h"
#include "datapack/registry.h"

namespace convoy::record {

namespace {

using ojson = nlohmann::ordered_json;
using datapack::kNdarrayBlobExtType;
using datapack::kNdarrayExtType;

constexpr char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// nlohmann's DOM builder (insertion order kept), refusing data nested deeper than the
// datapack codecs allow.
class DepthLimitedSax : public nlohmann::detail::json_sax_dom_parser<ojson> {
 public:
  using Base = nlohmann::detail::json_sax_dom_parser<ojson>;
  explicit DepthLimitedSax(ojson& out) : Base(out, /*allow_exceptions=*/true) {}
  bool start_object(std::size_t n) { return enter() && Base::start_object(n); }
  bool end_object() { return --depth_, Base::end_object(); }
  bool start_array(std::size_t n) { return enter() && Base::start_array(n); }
  bool end_array() { return --depth_, Base::end_array(); }

 private:
  bool enter() { return ++depth_ <= datapack::kMaxJsonDepth; }
  int depth_ = 0;
};

ojson parse_msgpack(const engine::DataPack& dp) {
  const std::string& raw = dp.json_msgpack();
  ojson value;
  try {
    DepthLimitedSax sax(value);
    if (!ojson::sax_parse(raw.begin(), raw.end(), &sax, ojson::input_format_t::msgpack))
      throw std::runtime_error(datapack::describe(dp.id()) + ": malformed or too deep MessagePack");
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(datapack::describe(dp.id()) + ": malformed MessagePack (" + e.what() +
                             ")");
  }
  return value;
}

struct ToText {
  const engine::DataPack& dp;
  const datapack::BlobReader& blobs;
  bool with_blobs;
  bool has_blobs = false;

  ojson operator()(const ojson& v) {
    switch (v.type()) {
      case ojson::value_t::object: {
        ojson out = ojson::object();
        for (auto it = v.begin(); it != v.end(); ++it) out[it.key()] = (*this)(it.value());
        return out;
      }
      case ojson::value_t::array: {
        ojson out = ojson::array();
        for (const auto& e : v) out.push_back((*this)(e));
        return out;
      }
      case ojson::value_t::number_float: {
        const double d = v.get<double>();
        if (std::isfinite(d)) return v;
        return {{"__float__", std::isnan(d) ? "nan" : d > 0 ? "inf" : "-inf"}};
      }
      case ojson::value_t::binary:
        return binary(v.get_binary());
      default:
        return v;
    }
  }

  ojson binary(const ojson::binary_t& bin) {
    std::string_view body(reinterpret_cast<const char*>(bin.data()), bin.size());
    if (!bin.has_subtype()) return {{"__bytes__", base64_encode(body)}};
    if (bin.subtype() != kNdarrayExtType && bin.subtype() != kNdarrayBlobExtType)
      return {{"__ext__", ojson::array({bin.subtype(), base64_encode(body)})}};
    datapack::NdarrayHeader header;
    std::string_view rest = datapack::parse_ndarray_header(body, &header);
    ojson a = ojson::object();
    a["dtype"] = header.dtype;
    a["shape"] = header.shape;
    if (bin.subtype() == kNdarrayExtType) {
      a["data"] = base64_encode(rest);
    } else {
      has_blobs = true;
      const std::string_view bytes = blobs.get(dp, datapack::parse_blob_index(rest));
      a["blob"] = true;
      if (with_blobs)
        a["data"] = base64_encode(bytes);
      else
        a["size"] = bytes.size();
    }
    return {{"__ndarray__", a}};
  }
};

struct FromText {
  engine::DataPack* dp;
  int placeholders = 0;

  static const ojson* tag(const ojson& v, const char* name) {
    if (!v.is_object() || v.size() != 1) return nullptr;
    auto it = v.find(name);
    return it == v.end() ? nullptr : &*it;
  }

  ojson operator()(const ojson& v) {
    if (v.is_array()) {
      ojson out = ojson::array();
      for (const auto& e : v) out.push_back((*this)(e));
      return out;
    }
    if (!v.is_object()) return v;
    if (const ojson* f = tag(v, "__float__")) {
      const std::string s = f->get<std::string>();
      if (s == "nan") return std::nan("");
      return s == "inf" ? HUGE_VAL : -HUGE_VAL;
    }
    if (const ojson* b = tag(v, "__bytes__")) return ojson::binary(bytes(b->get<std::string>()));
    if (const ojson* e = tag(v, "__ext__"))
      return ojson::binary(bytes(e->at(1).get<std::string>()), e->at(0).get<std::uint8_t>());
    if (const ojson* a = tag(v, "__ndarray__")) return ndarray(*a);
    ojson out = ojson::object();
    for (auto it = v.begin(); it != v.end(); ++it) out[it.key()] = (*this)(it.value());
    return out;
  }

  static std::vector<std::uint8_t> bytes(const std::string& b64) {
    std::string raw = base64_decode(b64);
    return {raw.begin(), raw.end()};
  }

  ojson ndarray(const ojson& a) {
    const auto shape = a.at("shape").get<std::vector<uint64_t>>();
    std::string body;
    datapack::append_ndarray_header(&body, a.at("dtype").get<std::string>(), shape);
    if (!a.value("blob", false)) {
      body += base64_decode(a.at("data").get<std::string>());
      return ojson::binary({body.begin(), body.end()}, kNdarrayExtType);
    }
    std::string* blob = dp->add_blobs()->mutable_inline_();
    if (a.contains("data")) {
      *blob = base64_decode(a.at("data").get<std::string>());
    } else {
      blob->assign(a.at("size").get<size_t>(), '\0');
      ++placeholders;
    }
    dp->mutable_blobs(dp->blobs_size() - 1)->set_size(blob->size());
    datapack::append_blob_index(&body, static_cast<uint32_t>(dp->blobs_size() - 1));
    return ojson::binary({body.begin(), body.end()}, kNdarrayBlobExtType);
  }
};

std::string dump(const ojson& v) { return v.dump(-1, ' ', false, ojson::error_handler_t::replace); }

// A protobuf datapack's message with its blobs put back (a camera's pixels inline).
std::string full_proto(const datapack::View& view) {
  if (view.proto_type() == datapack::type_name<data::Camera>()) {
    datapack::CameraImage img = datapack::read_camera(view);
    data::Camera cam;
    cam.set_image_height(img.height);
    cam.set_image_width(img.width);
    cam.set_image_depth(img.depth);
    cam.set_image_data(std::string(img.pixels));
    return cam.SerializeAsString();
  }
  return datapack::proto_bytes(view);
}

Encoded stub(const engine::DataPack& dp, const datapack::BlobReader& blobs) {
  const auto& payload = dp.proto();
  ojson s = ojson::object();
  s["type"] = payload.type_name();
  s["proto"] = base64_encode(payload.data());
  ojson fields = ojson::array(), sizes = ojson::array();
  for (const auto& bf : payload.blob_fields())
    fields.push_back(ojson::array({bf.field(), bf.index(), bf.blob()}));
  uint64_t total = 0;
  for (int i = 0; i < dp.blobs_size(); ++i) {
    const uint64_t n = blobs.get(dp, static_cast<uint32_t>(i)).size();
    sizes.push_back(n);
    total += n;
  }
  s["blob_fields"] = fields;
  s["blob_sizes"] = sizes;
  s["size"] = total;
  if (const auto* info = datapack::Registry::global().find(payload.type_name())) {
    std::unique_ptr<google::protobuf::Message> m(info->prototype->New());
    std::string text;
    google::protobuf::util::JsonPrintOptions options;
    options.preserve_proto_field_names = true;
    if (m->ParseFromString(payload.data()) &&
        google::protobuf::util::MessageToJsonString(*m, &text, options).ok())
      s["message"] = ojson::parse(text, nullptr, false);
  }
  Encoded out;
  out.kind = Kind::kStub;
  out.type = dp.id().type();
  out.has_blobs = dp.blobs_size() > 0;
  out.data = dump({{"__stub__", s}});
  return out;
}

}  // namespace

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::kJson:
      return "json";
    case Kind::kProtobuf:
      return "protobuf";
    case Kind::kStub:
      return "stub";
    case Kind::kEmpty:
      return "empty";
  }
  return "";
}

Kind kind_from_name(std::string_view name) {
  for (Kind k : {Kind::kJson, Kind::kProtobuf, Kind::kStub, Kind::kEmpty})
    if (name == kind_name(k)) return k;
  throw std::invalid_argument("unknown datapack kind '" + std::string(name) + "'");
}

Kind kind_of(const engine::DataPack& dp, bool with_blobs) {
  switch (dp.payload_case()) {
    case engine::DataPack::kJsonMsgpack:
      return Kind::kJson;
    case engine::DataPack::kProto: {
      const bool known = datapack::Registry::global().find(dp.proto().type_name()) != nullptr;
      return !known || (dp.blobs_size() > 0 && !with_blobs) ? Kind::kStub : Kind::kProtobuf;
    }
    default:
      return Kind::kEmpty;
  }
}

Encoded encode(const engine::DataPack& dp, const datapack::BlobReader& blobs, bool with_blobs) {
  Encoded out;
  out.type = dp.id().type();
  switch (dp.payload_case()) {
    case engine::DataPack::kJsonMsgpack: {
      out.kind = Kind::kJson;
      ToText convert{dp, blobs, with_blobs};
      ojson v;
      try {
        v = convert(parse_msgpack(dp));
      } catch (const std::runtime_error& e) {
        throw std::runtime_error(datapack::describe(dp.id()) + ": " + e.what());
      }
      if (!v.is_object()) v = ojson{{"__value__", std::move(v)}};
      out.has_blobs = convert.has_blobs;
      out.data = dump(v);
      return out;
    }
    case engine::DataPack::kProto: {
      const bool known = datapack::Registry::global().find(dp.proto().type_name()) != nullptr;
      if (!known || (dp.blobs_size() > 0 && !with_blobs)) return stub(dp, blobs);
      out.kind = Kind::kProtobuf;
      out.type = dp.proto().type_name();
      out.has_blobs = dp.blobs_size() > 0;
      out.data = full_proto(datapack::View(dp, blobs));
      return out;
    }
    default:
      out.kind = Kind::kEmpty;
      out.data = "{}";
      return out;
  }
}

engine::DataPack decode(Kind kind, const std::string& type, std::string_view data,
                        const std::string& name, const std::string& engine, int* placeholders) {
  engine::DataPack dp;
  dp.mutable_id()->set_name(name);
  dp.mutable_id()->set_engine_name(engine);
  dp.mutable_id()->set_type(type);
  try {
    switch (kind) {
      case Kind::kEmpty:
        return dp;
      case Kind::kProtobuf:
        dp.mutable_proto()->set_type_name(type);
        dp.mutable_proto()->set_data(std::string(data));
        return dp;
      case Kind::kJson: {
        ojson v = ojson::parse(data);
        if (const ojson* inner = FromText::tag(v, "__value__")) v = *inner;
        FromText convert{&dp};
        ojson value = convert(v);
        *placeholders += convert.placeholders;
        std::string* bytes = dp.mutable_json_msgpack();
        ojson::to_msgpack(value, nlohmann::detail::output_adapter<char>(*bytes));
        return dp;
      }
      case Kind::kStub: {
        const ojson s = ojson::parse(data).at("__stub__");
        auto* payload = dp.mutable_proto();
        payload->set_type_name(s.at("type").get<std::string>());
        payload->set_data(base64_decode(s.at("proto").get<std::string>()));
        for (const auto& f : s.at("blob_fields")) {
          auto* bf = payload->add_blob_fields();
          bf->set_field(f.at(0).get<uint32_t>());
          bf->set_index(f.at(1).get<uint32_t>());
          bf->set_blob(f.at(2).get<uint32_t>());
        }
        for (const auto& n : s.at("blob_sizes")) {
          auto* blob = dp.add_blobs();
          blob->mutable_inline_()->assign(n.get<size_t>(), '\0');
          blob->set_size(n.get<size_t>());
          ++*placeholders;
        }
        return dp;
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("datapack '" + name + "' of engine '" + engine +
                             "': malformed recorded " + kind_name(kind) + " message (" + e.what() +
                             ")");
  }
  return dp;
}

std::string base64_encode(std::string_view bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t n =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    out += kB64[n >> 18];
    out += kB64[(n >> 12) & 63];
    out += kB64[(n >> 6) & 63];
    out += kB64[n & 63];
  }
  if (i < bytes.size()) {
    uint32_t n = uint8_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= uint8_t(bytes[i + 1]) << 8;
    out += kB64[n >> 18];
    out += kB64[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kB64[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string base64_decode(std::string_view text) {
  static const auto table = [] {
    std::array<int8_t, 256> t{};
    t.fill(-1);
    for (int i = 0; i < 64; ++i) t[static_cast<uint8_t>(kB64[i])] = static_cast<int8_t>(i);
    return t;
  }();
  std::string out;
  out.reserve(text.size() / 4 * 3);
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=') break;
    const int v = table[static_cast<uint8_t>(c)];
    if (v < 0) throw std::runtime_error("bad base64 character");
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xFF);
    }
  }
  return out;
}

}  // namespace convoy::record
