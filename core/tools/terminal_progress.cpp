#include "terminal_progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>

namespace hedge::cli {

namespace {

std::atomic<bool> interrupt_flag{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT handler may only touch a lock-free atomic");

extern "C" void on_interrupt(int) { interrupt_flag.store(true); }

constexpr auto kRedrawInterval = std::chrono::milliseconds(100);
constexpr int kBarWidth = 30;

}  // namespace

void install_interrupt_handler() {
  struct sigaction action = {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // the second Ctrl-C gets the default: the process ends at once
  sigaction(SIGINT, &action, nullptr);
}

bool interrupted() { return interrupt_flag.load(); }

TerminalProgress::TerminalProgress(bool wanted) : shown_(wanted && isatty(STDERR_FILENO)) {
  winsize size = {};
  if (shown_ && ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) terminal_columns_ = size.ws_col;
}

TerminalProgress::~TerminalProgress() { clear(); }

bool TerminalProgress::update(double fraction, const std::string& stage) {
  if (interrupted()) return false;
  if (!shown_) return true;
  const int percent = std::clamp(static_cast<int>(fraction * 100.0), 0, 100);
  const auto now = Clock::now();
  const bool new_stage = stage != last_stage_;
  if (!new_stage && (percent == last_percent_ || now - last_draw_ < kRedrawInterval)) return true;
  last_draw_ = now;
  draw(percent, stage);
  return true;
}

void TerminalProgress::finish() {
  if (!shown_ || !line_open_) return;
  draw(100, last_stage_);
  std::fputc('\n', stderr);
  line_open_ = false;
}

void TerminalProgress::draw(int percent, const std::string& stage) {
  last_percent_ = percent;
  last_stage_ = stage;
  const int filled = percent * kBarWidth / 100;
  std::string tail = " [";
  tail.append(filled, '#').append(kBarWidth - filled, '-').append("] ").append(std::to_string(percent)).append(" %");
  // Stay within one terminal row: a wrapped line would not be redrawn in place by '\r'.
  const int room = std::max(0, terminal_columns_ - 1 - static_cast<int>(tail.size()));
  std::string line = "\r";
  line.append(stage, 0, room).append(tail).append("\033[K");
  std::fwrite(line.data(), 1, line.size(), stderr);
  line_open_ = true;
}

void TerminalProgress::clear() {
  if (!line_open_) return;
  std::fputs("\r\033[K", stderr);
  line_open_ = false;
}

}  // namespace hedge::cli
