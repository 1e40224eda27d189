// The settings schema against the boicp.v1 API: every field of
// RegistrationConfig and MapSettings is in the schema, and every schema
// field survives the messages both ways.

#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/rpc/settings_proto.hpp"
#include "boicp/util/types.hpp"
#include "settings_examples.hpp"

namespace boicp::settings {
namespace {

namespace pb = ::google::protobuf;

// Leaf field paths of `descriptor`, "sensor_model.prob_hit" style; a
// Vector3 counts as one leaf.
void CollectLeaves(const pb::Descriptor* descriptor, const std::string& prefix,
                   std::set<std::string>& out) {
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const pb::FieldDescriptor* field = descriptor->field(i);
    const pb::Descriptor* message = field->message_type();
    if (message != nullptr && message != v1::Vector3::descriptor()) {
      CollectLeaves(message, prefix + field->name() + ".", out);
    } else {
      out.insert(prefix + field->name());
    }
  }
}

std::set<std::string> SchemaProtoFields(ProtoMessage message) {
  std::set<std::string> fields;
  for (const SettingField& field : SettingSchema()) {
    if (field.message == message) fields.insert(field.proto_field);
  }
  return fields;
}

TEST(SettingsProto, TheSchemaNamesEveryFieldOfTheApi) {
  std::set<std::string> registration, map;
  CollectLeaves(v1::RegistrationConfig::descriptor(), "", registration);
  CollectLeaves(v1::MapSettings::descriptor(), "", map);
  EXPECT_EQ(SchemaProtoFields(ProtoMessage::kRegistrationConfig), registration);
  EXPECT_EQ(SchemaProtoFields(ProtoMessage::kMapSettings), map);
}

TEST(SettingsProto, EverySubmitFlagSurvivesTheMessages) {
  const RequestedSettings given = ParseFlags(kSubmit, ExampleArguments(kSubmit));
  const RequestedSettings read_back =
      rpc::SettingsFromProto(rpc::RegistrationConfigToProto(given), rpc::MapSettingsToProto(given));
  EXPECT_EQ(AllFields(read_back), AllFields(given));
}

TEST(SettingsProto, ProtoToConfigToProto) {
  RequestedSettings given = ParseFlags(kSubmit, ExampleArguments(kSubmit));
  // A config does not remember that it was fixed; the chosen settings the
  // daemon reports leave it false.
  given.fixed_settings = false;
  const v1::RegistrationConfig sent = rpc::RegistrationConfigToProto(given);
  const BoIcpConfig config = ConfigFromSettings(rpc::SettingsFromProto(sent, {}));
  const v1::RegistrationConfig reported =
      rpc::RegistrationConfigToProto(SettingsFromConfig(config));
  EXPECT_EQ(reported.SerializeAsString(), sent.SerializeAsString())
      << "sent " << sent.ShortDebugString() << "\nreported " << reported.ShortDebugString();
}

TEST(SettingsProto, TheBudgetCrossesTheApi) {
  RequestedSettings given;
  given.budget = "fixed";
  const v1::RegistrationConfig sent = rpc::RegistrationConfigToProto(given);
  EXPECT_EQ(sent.budget(), "fixed");
  EXPECT_EQ(ConfigFromSettings(rpc::SettingsFromProto(sent, {})).budget, Budget::kFixed);
  // An empty budget (a client from before it existed) is auto.
  EXPECT_EQ(ConfigFromSettings(rpc::SettingsFromProto({}, {})).budget, Budget::kAuto);
  v1::RegistrationConfig bad;
  bad.set_budget("nope");
  try {
    ConfigFromSettings(rpc::SettingsFromProto(bad, {}));
    FAIL() << "budget nope accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown budget 'nope' (expected auto or fixed)");
  }
}

TEST(SettingsProto, UnsetFieldsStayUnsetAndBadValuesNameTheField) {
  const v1::RegistrationConfig empty = rpc::RegistrationConfigToProto(RequestedSettings());
  EXPECT_FALSE(empty.has_voxel());
  EXPECT_FALSE(empty.has_rotation_bounds());
  EXPECT_EQ(empty.preset(), "C");
  const RequestedSettings defaults = rpc::SettingsFromProto({}, {});
  EXPECT_EQ(AllFields(defaults), AllFields(RequestedSettings()));

  v1::RegistrationConfig bad;
  bad.mutable_rotation_bounds()->set_x(-0.1);
  try {
    rpc::SettingsFromProto(bad, {});
    FAIL() << "negative bounds accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("config.rotation_bounds"));
  }
  RequestedSettings huge;
  huge.evaluation_points = uint64_t{1} << 40;
  EXPECT_THROW(rpc::RegistrationConfigToProto(huge), InputError);
}

}  // namespace
}  // namespace boicp::settings
