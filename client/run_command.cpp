#include "run_command.hpp"

#include <exception>
#include <iostream>

#include "boicp/util/types.hpp"
#include "commands.hpp"
#include "printable_text.hpp"

namespace boicp::cli {

int ReportCommandError(const std::string& command, const std::string& message, int code) {
  std::cerr << "boicp " << command << ": error: " << PrintableText(message) << std::endl;
  return code;
}

int RunCommand(const std::string& command, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    return ReportCommandError(command, e.what(), kBadInput);
  } catch (const LimitExceeded& e) {
    return ReportCommandError(command, e.what(), kBadInput);
  } catch (const std::exception& e) {
    return ReportCommandError(command, e.what(), kFailure);
  }
}

}  // namespace boicp::cli
