#include "datapack/proto.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/unknown_field_set.h>
#include <google/protobuf/wire_format.h>
#include <google/protobuf/wire_format_lite.h>

#include <cstring>
#include <vector>

namespace convoy::datapack {

namespace pb = google::protobuf;

namespace {

bool is_bytes(const pb::FieldDescriptor* f) {
  return f->type() == pb::FieldDescriptor::TYPE_BYTES && !f->is_extension();
}

// True if a top-level bytes field holds a value of kLargeBlobBytes or more.
bool has_large_bytes(const pb::Message& m) {
  const pb::Descriptor* d = m.GetDescriptor();
  const pb::Reflection* r = m.GetReflection();
  std::string scratch;
  for (int i = 0; i < d->field_count(); ++i) {
    const pb::FieldDescriptor* f = d->field(i);
    if (!is_bytes(f)) continue;
    if (!f->is_repeated()) {
      if (r->GetStringReference(m, f, &scratch).size() >= kLargeBlobBytes) return true;
      continue;
    }
    for (int j = 0, n = r->FieldSize(m, f); j < n; ++j)
      if (r->GetRepeatedStringReference(m, f, j, &scratch).size() >= kLargeBlobBytes) return true;
  }
  return false;
}

// Serializes `m` into `data` field by field, as SerializeToString would, except that the
// large values of top-level bytes fields go to blobs of `out` (one copy each, into the
// writer's arena when it has one).
void serialize_with_blobs(Builder& out, const pb::Message& m, engine::ProtoPayload* payload) {
  const pb::Reflection* r = m.GetReflection();
  m.ByteSizeLong();  // caches the sizes of sub-messages, which the field writer needs
  std::vector<const pb::FieldDescriptor*> fields;
  r->ListFields(m, &fields);
  auto to_blob = [&](const pb::FieldDescriptor* f, int index, const std::string& value) {
    uint32_t blob = 0;
    std::span<uint8_t> dst = out.reserve_blob(value.size(), &blob);
    std::memcpy(dst.data(), value.data(), value.size());
    count_copy(value.size());
    auto* bf = payload->add_blob_fields();
    bf->set_field(static_cast<uint32_t>(f->number()));
    bf->set_index(static_cast<uint32_t>(index));
    bf->set_blob(blob);
  };
  std::string* data = payload->mutable_data();
  data->clear();
  pb::io::StringOutputStream stream(data);
  pb::io::CodedOutputStream coded(&stream);
  std::string scratch;
  for (const pb::FieldDescriptor* f : fields) {
    if (is_bytes(f) && !f->is_repeated()) {
      const std::string& v = r->GetStringReference(m, f, &scratch);
      if (v.size() >= kLargeBlobBytes) {
        to_blob(f, 0, v);
        continue;
      }
    } else if (is_bytes(f)) {
      for (int j = 0, n = r->FieldSize(m, f); j < n; ++j) {
        const std::string& v = r->GetRepeatedStringReference(m, f, j, &scratch);
        if (v.size() >= kLargeBlobBytes) {
          to_blob(f, j, v);
          pb::internal::WireFormatLite::WriteBytes(f->number(), std::string(), &coded);
        } else {
          pb::internal::WireFormatLite::WriteBytes(f->number(), v, &coded);
        }
      }
      continue;
    }
    pb::internal::WireFormat::SerializeFieldWithCachedSizes(f, m, &coded);
  }
  pb::internal::WireFormat::SerializeUnknownFields(r->GetUnknownFields(m), &coded);
}

}  // namespace

void write_proto(Builder& out, const google::protobuf::Message& message) {
  auto* dp = out.message();
  const std::string& type = message.GetDescriptor()->full_name();
  dp->mutable_id()->set_type(type);
  auto* payload = dp->mutable_proto();
  payload->set_type_name(type);
  payload->clear_blob_fields();
  if (has_large_bytes(message))
    serialize_with_blobs(out, message, payload);
  else
    message.SerializeToString(payload->mutable_data());
}

void write_proto_bytes(Builder& out, const std::string& type, std::string_view bytes) {
  auto* dp = out.message();
  dp->mutable_id()->set_type(type);
  auto* payload = dp->mutable_proto();
  payload->set_type_name(type);
  payload->clear_blob_fields();
  payload->set_data(bytes.data(), bytes.size());
}

void read_proto(const View& in, google::protobuf::Message* message) {
  const std::string& want = message->GetDescriptor()->full_name();
  if (!in.is_proto() || in.proto_type() != want) {
    throw std::runtime_error(in.describe() + " holds " +
                             (in.is_proto()  ? "protobuf type " + in.proto_type()
                              : in.is_json() ? std::string("JSON")
                                             : std::string("nothing")) +
                             ", not " + want);
  }
  const engine::ProtoPayload& payload = in.message().proto();
  if (!message->ParseFromString(payload.data()))
    throw std::runtime_error(in.describe() + ": corrupt " + want);
  if (payload.blob_fields_size() == 0) return;
  const pb::Descriptor* d = message->GetDescriptor();
  const pb::Reflection* r = message->GetReflection();
  for (const auto& bf : payload.blob_fields()) {
    const pb::FieldDescriptor* f = d->FindFieldByNumber(static_cast<int>(bf.field()));
    if (!f || !is_bytes(f))
      throw std::runtime_error(in.describe() + ": a blob refers to field " +
                               std::to_string(bf.field()) + ", which is no bytes field of " + want);
    if (bf.blob() >= static_cast<uint32_t>(in.message().blobs_size()))
      throw std::runtime_error(in.describe() + ": field " + f->name() +
                               " refers to a missing blob");
    std::string_view bytes = in.blob(bf.blob());
    count_copy(bytes.size());
    if (!f->is_repeated()) {
      r->SetString(message, f, std::string(bytes));
    } else if (bf.index() < static_cast<uint32_t>(r->FieldSize(*message, f))) {
      r->SetRepeatedString(message, f, static_cast<int>(bf.index()), std::string(bytes));
    } else {
      throw std::runtime_error(in.describe() + ": a blob refers to element " +
                               std::to_string(bf.index()) + " of field " + f->name() +
                               ", which has " + std::to_string(r->FieldSize(*message, f)));
    }
  }
}

std::string proto_bytes(const View& in) {
  const engine::ProtoPayload& payload = in.message().proto();
  if (payload.blob_fields_size() == 0) return payload.data();
  pb::UnknownFieldSet fields;
  if (!fields.ParseFromString(payload.data()))
    throw std::runtime_error(in.describe() + ": corrupt " + in.proto_type());
  for (const auto& bf : payload.blob_fields()) {
    if (bf.blob() >= static_cast<uint32_t>(in.message().blobs_size()))
      throw std::runtime_error(in.describe() + ": field " + std::to_string(bf.field()) +
                               " refers to a missing blob");
    const std::string_view bytes = in.blob(bf.blob());
    std::string* target = nullptr;
    uint32_t seen = 0;
    for (int i = 0; i < fields.field_count() && !target; ++i) {
      pb::UnknownField* f = fields.mutable_field(i);
      if (static_cast<uint32_t>(f->number()) == bf.field() &&
          f->type() == pb::UnknownField::TYPE_LENGTH_DELIMITED && seen++ == bf.index())
        target = f->mutable_length_delimited();
    }
    if (!target) target = fields.AddLengthDelimited(static_cast<int>(bf.field()));
    count_copy(bytes.size());
    target->assign(bytes.data(), bytes.size());
  }
  std::string out;
  fields.SerializeToString(&out);
  return out;
}

}  // namespace convoy::datapack
