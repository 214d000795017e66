// The configuration: the main file and one drop-in (the input's part after its first NUL byte), read as
// everytouchd reads them. Bad text may only give io::InputError; anything else is a finding.
#include <cstdint>

#include "fuzz_input.h"
#include "io/input_error.h"
#include "service/config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    const auto parts = fuzz::splitParts(data, size, 2);
    const std::filesystem::path main = fuzz::scratchDirectory() / "everytouchd.conf";
    const std::filesystem::path dropIns = service::dropInDirectory(main);
    fuzz::writeFile(main, parts[0]);
    std::filesystem::create_directories(dropIns);
    const std::filesystem::path dropIn = dropIns / "50-fuzz.conf";
    if (parts.size() > 1)
        fuzz::writeFile(dropIn, parts[1]);
    else
        std::filesystem::remove(dropIn);
    try {
        (void)service::loadConfig(main, true);
    } catch (const io::InputError&) {
    }
    return 0;
}
