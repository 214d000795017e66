#include "core/frame_pairer.h"

namespace everytouch::core {

std::optional<FramePair> FramePairer::push(const Frame& frame) {
    std::optional<FramePair> pair;
    if (previous_ && previous_->polarity == opposite(frame.polarity) && previous_->index + 1 == frame.index) {
        pair.emplace();
        pair->positive = frame.polarity == Polarity::Positive ? frame : *previous_;
        pair->negative = frame.polarity == Polarity::Positive ? *previous_ : frame;
    }
    previous_ = frame;
    return pair;
}

}  // namespace everytouch::core
