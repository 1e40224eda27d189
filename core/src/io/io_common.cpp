// File checks and locale-independent number parsing shared by the loaders.

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "io/io_readers.hpp"

namespace boicp::io_detail {

namespace {

std::string OsReason(int error) {
  return error != 0 ? std::strerror(error) : std::string("unknown error");
}

}  // namespace

void RequireReadableFile(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) {
    throw InputError(path + ": no such file");
  }
  if (ec) throw InputError(path + ": cannot access (" + ec.message() + ")");
  if (std::filesystem::is_directory(status)) {
    throw InputError(path + ": is a directory, not a file");
  }
  // fopen reports the OS reason through errno, which std::ifstream does not
  // promise to do.
  errno = 0;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw InputError(path + ": cannot open for reading (" + OsReason(errno) + ")");
  }
  std::fclose(file);
}

std::ifstream OpenOrThrow(const std::string& path, std::ios::openmode mode) {
  RequireReadableFile(path);
  std::ifstream in(path, mode);
  if (!in) throw InputError(path + ": cannot open for reading");
  return in;
}

uint64_t FileSizeOrThrow(const std::string& path) {
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path + ": cannot get file size (" + ec.message() + ")");
  return static_cast<uint64_t>(size);
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t pos = 0;
  while (true) {
    while (pos < line.size() && IsFieldSeparator(line[pos])) ++pos;
    if (pos == line.size()) return fields;
    const size_t start = pos;
    while (pos < line.size() && !IsFieldSeparator(line[pos])) ++pos;
    fields.push_back(line.substr(start, pos - start));
  }
}

std::optional<double> ParseNumber(std::string_view token) {
  // from_chars rejects a leading '+', which some writers emit ("%+f"); strip
  // exactly one so that "+-1" stays invalid.
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    if (!token.empty() && (token.front() == '+' || token.front() == '-')) return std::nullopt;
  }
  if (token.empty()) return std::nullopt;
  double value = 0.0;
  const char* end = token.data() + token.size();
  const auto [ptr, error] = std::from_chars(token.data(), end, value);
  if (error != std::errc() || ptr != end) return std::nullopt;
  return value;
}

bool IsBlankOrComment(std::string_view line) {
  const size_t first = line.find_first_not_of(" \t\r");
  return first == std::string_view::npos || line[first] == '#';
}

std::vector<double> ReadNumbersFile(const std::string& path) {
  std::ifstream in = OpenOrThrow(path);
  std::vector<double> numbers;
  std::string line;
  for (size_t line_number = 1; std::getline(in, line); ++line_number) {
    if (IsBlankOrComment(line)) continue;
    for (std::string_view field : SplitFields(line)) {
      const std::optional<double> value = ParseNumber(field);
      if (!value) {
        throw InputError(path + ":" + std::to_string(line_number) + ": '" + std::string(field) +
                         "' is not a number");
      }
      numbers.push_back(*value);
    }
  }
  if (in.bad()) throw InputError(path + ": read error");
  return numbers;
}

}  // namespace boicp::io_detail
