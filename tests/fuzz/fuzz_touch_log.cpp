// The touch log (JSON lines) as everytouch-eval reads it. Bad text may only give io::InputError; anything
// else is a finding.
#include <cstdint>

#include "fuzz_input.h"
#include "io/touch_log.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    fuzz::readAsFile("touches.jsonl", data, size,
                     [](const std::filesystem::path& path) { (void)io::readTouchLog(path); });
    return 0;
}
