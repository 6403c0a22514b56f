#include "datapack/json.h"

#include <stdexcept>

namespace convoy::datapack {

namespace {

// nlohmann's DOM builder, refusing containers nested deeper than kMaxJsonDepth: its
// MessagePack reader recurses once per level (10,000 levels, 10 KB, overflowed the stack).
class DepthLimitedSax : public nlohmann::detail::json_sax_dom_parser<nlohmann::json> {
 public:
  using Base = nlohmann::detail::json_sax_dom_parser<nlohmann::json>;
  explicit DepthLimitedSax(nlohmann::json& out) : Base(out, /*allow_exceptions=*/true) {}
  bool start_object(std::size_t n) { return enter() && Base::start_object(n); }
  bool end_object() { return leave() && Base::end_object(); }
  bool start_array(std::size_t n) { return enter() && Base::start_array(n); }
  bool end_array() { return leave() && Base::end_array(); }
  bool too_deep() const { return too_deep_; }

 private:
  bool enter() {
    too_deep_ = ++depth_ > kMaxJsonDepth;
    return !too_deep_;
  }
  bool leave() {
    --depth_;
    return true;
  }
  int depth_ = 0;
  bool too_deep_ = false;
};

}  // namespace

std::string describe(const engine::DataPackId& id) {
  std::string s = "datapack '" + id.name() + "'";
  if (!id.engine_name().empty()) s += " of engine '" + id.engine_name() + "'";
  return s;
}
std::string View::describe() const { return datapack::describe(dp_.id()); }
std::string Builder::describe() const { return datapack::describe(dp_->id()); }

void write_json(Builder& out, const nlohmann::json& value) {
  auto* dp = out.message();
  dp->mutable_id()->set_type(std::string(kJsonType));
  std::string* bytes = dp->mutable_json_msgpack();
  bytes->clear();
  nlohmann::json::to_msgpack(value, nlohmann::detail::output_adapter<char>(*bytes));
}

nlohmann::json read_json(const View& in) {
  if (!in.is_json()) throw std::runtime_error(in.describe() + " holds no JSON value");
  const std::string& raw = in.message().json_msgpack();
  nlohmann::json value;
  try {
    DepthLimitedSax sax(value);
    if (!nlohmann::json::sax_parse(raw.begin(), raw.end(), &sax,
                                   nlohmann::json::input_format_t::msgpack)) {
      throw std::runtime_error(in.describe() + ": " +
                               (sax.too_deep() ? "MessagePack nested deeper than " +
                                                     std::to_string(kMaxJsonDepth) + " levels"
                                               : std::string("malformed MessagePack")));
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(in.describe() + ": malformed MessagePack (" + e.what() + ")");
  }
  return value;
}

nlohmann::json ndarray_json(Builder& out, std::string_view dtype, std::span<const uint64_t> shape,
                            std::string_view bytes) {
  std::vector<uint8_t> body;
  append_ndarray_header(&body, dtype, shape);
  if (bytes.size() >= kLargeBlobBytes) {
    append_blob_index(&body, out.add_blob(bytes));
    return nlohmann::json::binary(std::move(body), kNdarrayBlobExtType);
  }
  body.insert(body.end(), bytes.begin(), bytes.end());
  return nlohmann::json::binary(std::move(body), kNdarrayExtType);
}

NdarrayRef read_ndarray(const View& in, const nlohmann::json& value) {
  if (!value.is_binary()) throw std::runtime_error(in.describe() + ": not a numpy array");
  const auto& bin = value.get_binary();
  if (!bin.has_subtype() ||
      (bin.subtype() != kNdarrayExtType && bin.subtype() != kNdarrayBlobExtType))
    throw std::runtime_error(in.describe() + ": not a numpy array");
  NdarrayRef ref;
  std::string_view body(reinterpret_cast<const char*>(bin.data()), bin.size());
  try {
    ref.data = parse_ndarray_header(body, &ref.header);
    if (bin.subtype() == kNdarrayBlobExtType)
      ref.data = in.blob(parse_blob_index(ref.data), &ref.in_shm);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(in.describe() + ": " + e.what());
  }
  const size_t item = dtype_size(ref.header.dtype);
  const uint64_t count = ref.header.count();
  if (item == 0 || count > UINT64_MAX / item || count * item != ref.data.size())
    throw std::runtime_error(in.describe() + ": numpy array of " + std::to_string(ref.data.size()) +
                             " bytes does not match its dtype '" + ref.header.dtype +
                             "' and shape");
  return ref;
}

}  // namespace convoy::datapack
