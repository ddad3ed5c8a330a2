// plumb/io/ros/read_ahead.cc — read_ahead.h's pipeline, on TBB's threads.
#include "plumb/io/ros/read_ahead.h"

#include <oneapi/tbb/parallel_pipeline.h>

namespace plumb::io::detail {

void ReadAhead(std::size_t slots, const std::function<bool(std::size_t slot)>& next,
               const std::function<void(std::size_t slot)>& prepare,
               const std::function<void(std::size_t slot)>& consume) {
  std::size_t framed = 0;  // items framed so far; the next goes into slot framed % slots
  const auto frame = [&](tbb::flow_control& control) -> std::size_t {
    const std::size_t slot = framed % slots;
    if (!next(slot)) {
      control.stop();
      return 0;
    }
    ++framed;
    return slot;
  };
  const auto ready = [&](std::size_t slot) {
    prepare(slot);
    return slot;
  };
  const auto use = [&](std::size_t slot) { consume(slot); };
  tbb::parallel_pipeline(
      slots, tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order, frame) &
                 tbb::make_filter<std::size_t, std::size_t>(tbb::filter_mode::parallel, ready) &
                 tbb::make_filter<std::size_t, void>(tbb::filter_mode::serial_in_order, use));
}

}  // namespace plumb::io::detail
