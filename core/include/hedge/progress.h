// Progress and cancellation, as hosts offer them (MeshLab's callback, Blender's bar).
#pragma once

#include <functional>
#include <string>

#include "hedge/error.h"

namespace hedge {

//! Receives (fraction 0..1, stage name); returns false to ask the operation to stop.
class Progress {
 public:
  using Callback = std::function<bool(double fraction, const std::string& stage)>;
  Progress() = default;
  explicit Progress(Callback callback) : callback_(std::move(callback)) {}

  //! Reports progress; throws Cancelled when the callback asks to stop.
  void update(double fraction, const std::string& stage) {
    if (callback_ && !callback_(fraction, stage)) throw Cancelled();
  }
  static Progress& none() {
    static thread_local Progress silent;
    return silent;
  }

 private:
  Callback callback_;
};

}  // namespace hedge
