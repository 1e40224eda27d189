#include "boicp/rpc/pair_result_proto.hpp"

#include <limits>
#include <stdexcept>
#include <type_traits>

#include "boicp/rpc/proto_convert.hpp"
#include "boicp/settings/rung_summary.hpp"

namespace boicp::rpc {
namespace {

namespace pb = ::google::protobuf;

const pb::FieldDescriptor* FieldNamed(const char* name) {
  const pb::FieldDescriptor* field = v1::PairResult::descriptor()->FindFieldByName(name);
  if (field == nullptr) throw std::logic_error(std::string("PairResult has no field ") + name);
  return field;
}

template <typename T>
void SetValue(v1::PairResult* out, const pb::FieldDescriptor* field, const T& value) {
  const pb::Reflection* reflection = out->GetReflection();
  if constexpr (std::is_same_v<T, Transform>) {
    TransformToProto(value, static_cast<v1::Transform*>(reflection->MutableMessage(out, field)));
  } else if constexpr (std::is_same_v<T, std::optional<double>>) {
    if (value) reflection->SetDouble(out, field, *value);
  } else if constexpr (std::is_same_v<T, double>) {
    reflection->SetDouble(out, field, value);
  } else if constexpr (std::is_same_v<T, bool>) {
    reflection->SetBool(out, field, value);
  } else if constexpr (std::is_same_v<T, Rung>) {
    reflection->SetString(out, field, RungName(value));
  } else if constexpr (std::is_same_v<T, std::string>) {
    reflection->SetString(out, field, value);
  } else if constexpr (std::is_same_v<T, int>) {
    reflection->SetUInt32(out, field, static_cast<uint32_t>(std::max(value, 0)));
  } else if constexpr (std::is_same_v<T, uint64_t>) {
    reflection->SetUInt64(out, field, value);
  } else {
    throw std::logic_error(std::string("PairResult field ") + field->name() +
                           " has no place in the API");
  }
}

template <typename T>
T GetValue(const v1::PairResult& in, const pb::FieldDescriptor* field) {
  const pb::Reflection* reflection = in.GetReflection();
  if constexpr (std::is_same_v<T, Transform>) {
    return TransformFromProto(static_cast<const v1::Transform&>(reflection->GetMessage(in, field)),
                              "pair." + field->name());
  } else if constexpr (std::is_same_v<T, std::optional<double>>) {
    if (!reflection->HasField(in, field)) return std::nullopt;
    return reflection->GetDouble(in, field);
  } else if constexpr (std::is_same_v<T, double>) {
    return reflection->GetDouble(in, field);
  } else if constexpr (std::is_same_v<T, bool>) {
    return reflection->GetBool(in, field);
  } else if constexpr (std::is_same_v<T, Rung>) {
    const std::string name = AnsweredBy(in);
    const std::optional<Rung> rung = settings::RungFromName(name);
    if (!rung) throw InputError("pair." + field->name() + ": unknown rung '" + name + "'");
    return *rung;
  } else if constexpr (std::is_same_v<T, std::string>) {
    return reflection->GetString(in, field);
  } else if constexpr (std::is_same_v<T, int>) {
    const uint32_t value = reflection->GetUInt32(in, field);
    return static_cast<int>(std::min<uint32_t>(value, std::numeric_limits<int>::max()));
  } else if constexpr (std::is_same_v<T, uint64_t>) {
    return reflection->GetUInt64(in, field);
  } else {
    throw std::logic_error(std::string("PairResult field ") + field->name() +
                           " has no place in the API");
  }
}

}  // namespace

void PairResultToProto(const PairResult& result, v1::PairResult* out) {
  out->set_source(static_cast<uint32_t>(result.pair.source));
  out->set_target(static_cast<uint32_t>(result.pair.target));
  for (const PairResultField& field : PairResultFields()) {
    if ((field.formats & kPairApi) == 0) continue;
    std::visit([&](auto member) { SetValue(out, FieldNamed(field.name), result.*member); },
               field.member);
  }
}

PairResult PairResultFromProto(const v1::PairResult& message) {
  PairResult result;
  result.pair = {static_cast<int>(message.source()), static_cast<int>(message.target())};
  for (const PairResultField& field : PairResultFields()) {
    if ((field.formats & kPairApi) == 0) continue;
    std::visit(
        [&](auto member) {
          using T = std::decay_t<decltype(result.*member)>;
          result.*member = GetValue<T>(message, FieldNamed(field.name));
        },
        field.member);
  }
  // Results stored before confidence was calibrated carry no doubtful flag.
  if (!message.has_doubtful()) result.confidence = 1.0;
  return result;
}

}  // namespace boicp::rpc
