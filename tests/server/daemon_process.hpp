#pragma once
// boicpd as a child process, the way scripts run it: started with
// --listen 127.0.0.1:0, its real port read from the "listening on" log line.

#include <sys/types.h>

#include <string>
#include <vector>

namespace boicp::test {

class DaemonProcess {
 public:
  /// Starts BOICPD_PATH with --listen 127.0.0.1:0 and `args`, its output in
  /// `log_path`, and waits (up to 60 s) for it to listen. Throws
  /// std::runtime_error with the log when it exits or never listens.
  DaemonProcess(const std::vector<std::string>& args, const std::string& log_path);
  /// Kills the daemon (SIGKILL) if it still runs.
  ~DaemonProcess();
  DaemonProcess(const DaemonProcess&) = delete;
  DaemonProcess& operator=(const DaemonProcess&) = delete;

  const std::string& address() const { return address_; }
  int port() const { return port_; }
  pid_t pid() const { return pid_; }

  void Signal(int signal_number) const;
  /// Waits for the process to exit, up to `timeout_s`; returns its exit
  /// code, 128 + signal when a signal ended it, or -1 on timeout.
  int Wait(double timeout_s);
  std::string Log() const;

 private:
  pid_t pid_ = -1;
  std::string log_path_;
  std::string address_;
  int port_ = 0;
};

}  // namespace boicp::test
