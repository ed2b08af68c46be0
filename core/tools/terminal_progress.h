// The command line's progress bar on stderr and its Ctrl-C: terminal code stays out of the core,
// which only sees a hedge::Progress callback that returns false once the user has pressed Ctrl-C.
#pragma once

#include <chrono>
#include <string>

namespace hedge::cli {

//! Installs the SIGINT handler: the first Ctrl-C only raises a flag (the operation then stops
//! through its own cancel path), and restores the default so a second one ends the process at once.
void install_interrupt_handler();

//! True once Ctrl-C has been pressed.
bool interrupted();

//! One line on stderr, redrawn in place: stage, bar, percent. Draws nothing unless `wanted` and
//! stderr is a terminal; still answers interrupted() either way, so --quiet runs cancel too.
class TerminalProgress {
 public:
  explicit TerminalProgress(bool wanted);
  ~TerminalProgress();  // clears an unfinished line, so an error message starts on a clean line
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  //! For hedge::Progress: draws at most ~10 times a second or on a new stage; false after Ctrl-C.
  bool update(double fraction, const std::string& stage);
  //! Draws the last stage at 100 % and ends the line, before the report goes to stdout.
  void finish();

 private:
  void draw(int percent, const std::string& stage);
  void clear();

  using Clock = std::chrono::steady_clock;
  bool shown_ = false;
  bool line_open_ = false;
  int terminal_columns_ = 80;
  int last_percent_ = -1;
  std::string last_stage_;
  Clock::time_point last_draw_{};
};

}  // namespace hedge::cli
