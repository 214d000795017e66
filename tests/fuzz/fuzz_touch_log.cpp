// The touch log (JSON lines) as everytouch-eval reads it. Bad text may only give io::InputError; anything
// else is a finding.
#include <cstdint>
#include <string_view>

#include "fuzz_input.h"
#include "io/input_error.h"
#include "io/touch_log.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    const std::filesystem::path path = fuzz::scratchDirectory() / "touches.jsonl";
    fuzz::writeFile(path, std::string_view(reinterpret_cast<const char*>(data), size));
    try {
        (void)io::readTouchLog(path);
    } catch (const io::InputError&) {
    }
    return 0;
}
