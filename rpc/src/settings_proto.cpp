#include "boicp/rpc/settings_proto.hpp"

#include <cmath>
#include <limits>
#include <type_traits>

#include "boicp/rpc/proto_convert.hpp"
#include "boicp/settings/setting_schema.hpp"

namespace boicp::rpc {
namespace {

namespace pb = ::google::protobuf;
using settings::ProtoMessage;
using settings::RequestedSettings;
using settings::SettingField;

// The message holding the last component of `path` ("sensor_model.prob_hit")
// inside `root`, and that component's descriptor.
template <typename MessagePtr>
std::pair<MessagePtr, const pb::FieldDescriptor*> Resolve(MessagePtr root,
                                                          const std::string& path) {
  MessagePtr message = root;
  size_t start = 0;
  for (size_t dot = path.find('.'); dot != std::string::npos; dot = path.find('.', start)) {
    const pb::FieldDescriptor* part =
        message->GetDescriptor()->FindFieldByName(path.substr(start, dot - start));
    if constexpr (std::is_const_v<std::remove_pointer_t<MessagePtr>>) {
      message = &message->GetReflection()->GetMessage(*message, part);
    } else {
      message = message->GetReflection()->MutableMessage(message, part);
    }
    start = dot + 1;
  }
  const pb::FieldDescriptor* field = message->GetDescriptor()->FindFieldByName(path.substr(start));
  if (field == nullptr) throw std::logic_error("schema names no proto field '" + path + "'");
  return {message, field};
}

void SetUnsigned(pb::Message* message, const pb::FieldDescriptor* field, uint64_t value,
                 const std::string& name) {
  const pb::Reflection* reflection = message->GetReflection();
  if (field->cpp_type() == pb::FieldDescriptor::CPPTYPE_UINT32) {
    if (value > std::numeric_limits<uint32_t>::max()) {
      throw InputError(name + ": " + std::to_string(value) + " is over the API's limit of " +
                       std::to_string(std::numeric_limits<uint32_t>::max()));
    }
    reflection->SetUInt32(message, field, static_cast<uint32_t>(value));
  } else {
    reflection->SetUInt64(message, field, value);
  }
}

template <typename T>
void SetValue(pb::Message* message, const pb::FieldDescriptor* field, const T& value,
              const std::string& name) {
  const pb::Reflection* reflection = message->GetReflection();
  if constexpr (std::is_same_v<T, std::string>) {
    reflection->SetString(message, field, value);
  } else if constexpr (std::is_same_v<T, bool>) {
    reflection->SetBool(message, field, value);
  } else if constexpr (std::is_same_v<T, double>) {
    reflection->SetDouble(message, field, value);
  } else if constexpr (std::is_same_v<T, int>) {
    reflection->SetInt32(message, field, value);
  } else if constexpr (std::is_same_v<T, uint64_t>) {
    SetUnsigned(message, field, value, name);
  } else {
    static_assert(std::is_same_v<T, Eigen::Vector3d>);
    reflection->MutableMessage(message, field)->CopyFrom(PointToProto(value));
  }
}

// A field without presence counts as given when it differs from its zero value.
template <typename T>
bool Given(const pb::Message& message, const pb::FieldDescriptor* field, const T& value) {
  if (field->has_presence()) return message.GetReflection()->HasField(message, field);
  if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    return false;  // message fields always have presence
  } else {
    return value != T{};
  }
}

template <typename T>
T GetValue(const pb::Message& message, const pb::FieldDescriptor* field, const std::string& name) {
  const pb::Reflection* reflection = message.GetReflection();
  if constexpr (std::is_same_v<T, std::string>) {
    return reflection->GetString(message, field);
  } else if constexpr (std::is_same_v<T, bool>) {
    return reflection->GetBool(message, field);
  } else if constexpr (std::is_same_v<T, double>) {
    const double value = reflection->GetDouble(message, field);
    if (!std::isfinite(value)) throw InputError(name + ": non-finite value");
    return value;
  } else if constexpr (std::is_same_v<T, int>) {
    return reflection->GetInt32(message, field);
  } else if constexpr (std::is_same_v<T, uint64_t>) {
    return field->cpp_type() == pb::FieldDescriptor::CPPTYPE_UINT32
               ? reflection->GetUInt32(message, field)
               : reflection->GetUInt64(message, field);
  } else {
    static_assert(std::is_same_v<T, Eigen::Vector3d>);
    // Every three-number setting is a set of half-widths of the search box.
    const Point point = PointFromProto(
        static_cast<const v1::Vector3&>(reflection->GetMessage(message, field)), name);
    if ((point.array() < 0.0).any()) throw InputError(name + ": half-widths must be >= 0");
    return point;
  }
}

void WriteFields(ProtoMessage which, const RequestedSettings& settings, pb::Message* root) {
  for (const SettingField& field : settings::SettingSchema()) {
    if (field.message != which) continue;
    const auto [message, descriptor] = Resolve(root, field.proto_field);
    const std::string name = ProtoFieldPath(field);
    std::visit(
        [&, message = message, descriptor = descriptor](const auto& binding) {
          const auto& value = settings.*binding.requested;
          if constexpr (settings::kIsPlainBinding<std::decay_t<decltype(binding)>>) {
            SetValue(message, descriptor, value, name);
          } else if (value) {
            SetValue(message, descriptor, *value, name);
          }
        },
        field.binding);
  }
}

void ReadFields(ProtoMessage which, const pb::Message& root, RequestedSettings& settings) {
  for (const SettingField& field : settings::SettingSchema()) {
    if (field.message != which) continue;
    const auto [message, descriptor] = Resolve(&root, field.proto_field);
    const std::string name = ProtoFieldPath(field);
    std::visit(
        [&, message = message, descriptor = descriptor](const auto& binding) {
          using T = typename settings::BindingValue<std::decay_t<decltype(binding)>>::type;
          const T value = GetValue<T>(*message, descriptor, name);
          if (Given(*message, descriptor, value)) settings.*binding.requested = value;
        },
        field.binding);
  }
}

}  // namespace

std::string ProtoFieldPath(const SettingField& field) {
  const char* prefix = field.message == ProtoMessage::kRegistrationConfig ? "config." : "map.";
  return prefix + std::string(field.proto_field);
}

v1::RegistrationConfig RegistrationConfigToProto(const RequestedSettings& settings) {
  v1::RegistrationConfig proto;
  WriteFields(ProtoMessage::kRegistrationConfig, settings, &proto);
  return proto;
}

v1::MapSettings MapSettingsToProto(const RequestedSettings& settings) {
  v1::MapSettings proto;
  WriteFields(ProtoMessage::kMapSettings, settings, &proto);
  return proto;
}

RequestedSettings SettingsFromProto(const v1::RegistrationConfig& config,
                                    const v1::MapSettings& map) {
  RequestedSettings settings;
  ReadFields(ProtoMessage::kRegistrationConfig, config, settings);
  ReadFields(ProtoMessage::kMapSettings, map, settings);
  return settings;
}

}  // namespace boicp::rpc
