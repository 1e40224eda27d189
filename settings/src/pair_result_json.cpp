#include "boicp/settings/pair_result_json.hpp"

#include <type_traits>

#include "boicp/settings/rung_summary.hpp"
#include "boicp/util/types.hpp"

namespace boicp::settings {
namespace {

using nlohmann::json;

template <typename T>
inline constexpr bool kIsMatrix = std::is_base_of_v<Eigen::MatrixBase<T>, T>;

template <typename T>
json ValueToJson(const T& value) {
  if constexpr (kIsMatrix<T>) {
    json rows = json::array();
    for (int i = 0; i < value.rows(); ++i) {
      json row = json::array();
      for (int j = 0; j < value.cols(); ++j) row.push_back(value(i, j));
      rows.push_back(std::move(row));
    }
    return rows;
  } else if constexpr (std::is_same_v<T, std::optional<double>>) {
    return value ? json(*value) : json(nullptr);
  } else if constexpr (std::is_same_v<T, Rung>) {
    return RungName(value);
  } else if constexpr (std::is_same_v<T, std::optional<std::vector<FreeSlide>>>) {
    return value ? FreeSlidesToJson(*value) : json(nullptr);
  } else {
    return value;
  }
}

template <typename T>
T ValueFromJson(const json& value) {
  if constexpr (kIsMatrix<T>) {
    T matrix;
    if (!value.is_array() || value.size() != static_cast<size_t>(matrix.rows()))
      throw InputError("expected " + std::to_string(matrix.rows()) + " rows");
    for (int i = 0; i < matrix.rows(); ++i) {
      const json& row = value[static_cast<size_t>(i)];
      if (!row.is_array() || row.size() != static_cast<size_t>(matrix.cols()))
        throw InputError("expected rows of " + std::to_string(matrix.cols()) + " numbers");
      for (int j = 0; j < matrix.cols(); ++j)
        matrix(i, j) = row[static_cast<size_t>(j)].get<double>();
    }
    return matrix;
  } else if constexpr (std::is_same_v<T, std::optional<double>>) {
    if (value.is_null()) return std::nullopt;
    return value.get<double>();
  } else if constexpr (std::is_same_v<T, Rung>) {
    const std::string name = value.get<std::string>();
    const std::optional<Rung> rung = RungFromName(name);
    if (!rung) throw InputError("unknown rung '" + name + "'");
    return *rung;
  } else if constexpr (std::is_same_v<T, std::optional<std::vector<FreeSlide>>>) {
    if (value.is_null()) return std::nullopt;
    if (!value.is_array()) throw InputError("expected a list of slides");
    std::vector<FreeSlide> slides;
    for (const json& slide : value) slides.push_back(FreeSlideFromJson(slide));
    return slides;
  } else {
    return value.get<T>();
  }
}

}  // namespace

json FreeSlidesToJson(const std::vector<FreeSlide>& slides) {
  json out = json::array();
  for (const FreeSlide& slide : slides) {
    out.push_back({{"axis", {slide.axis.x(), slide.axis.y(), slide.axis.z()}},
                   {"extent_m", slide.extent},
                   {"across_share", slide.across_share}});
  }
  return out;
}

FreeSlide FreeSlideFromJson(const json& in) {
  const json& axis = in.at("axis");
  if (!axis.is_array() || axis.size() != 3) throw InputError("an axis is 3 numbers");
  FreeSlide slide;
  slide.axis = {axis[0].get<double>(), axis[1].get<double>(), axis[2].get<double>()};
  slide.extent = in.at("extent_m").get<double>();
  slide.across_share = in.at("across_share").get<double>();
  return slide;
}

json PairResultToJson(const PairResult& result, PairResultFormat format) {
  json out = {{"source", result.pair.source}, {"target", result.pair.target}};
  for (const PairResultField& field : PairResultFields()) {
    if ((field.formats & format) == 0) continue;
    std::visit([&](auto member) { out[field.name] = ValueToJson(result.*member); }, field.member);
  }
  return out;
}

PairResult PairResultFromJson(const json& in, PairResultFormat format) {
  PairResult result;
  const auto read = [&](const char* key, auto& value) {
    try {
      value = ValueFromJson<std::decay_t<decltype(value)>>(in.at(key));
    } catch (const std::exception& e) {
      throw InputError(std::string(key) + ": " + e.what());
    }
  };
  read("source", result.pair.source);
  read("target", result.pair.target);
  for (const PairResultField& field : PairResultFields()) {
    if ((field.formats & format) == 0) continue;
    std::visit([&](auto member) { read(field.name, result.*member); }, field.member);
  }
  return result;
}

}  // namespace boicp::settings
