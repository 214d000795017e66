// The calibration file (/var/lib/everytouch/calibration.yml), read as everytouchd reads it at start and on
// reload. Bad text may only give io::InputError; anything else is a finding.
#include <cstdint>
#include <string_view>

#include "fuzz_input.h"
#include "io/calibration_file.h"
#include "io/input_error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    const std::filesystem::path path = fuzz::scratchDirectory() / "calibration.yml";
    fuzz::writeFile(path, std::string_view(reinterpret_cast<const char*>(data), size));
    try {
        (void)io::readCalibrationFile(path);
    } catch (const io::InputError&) {
    }
    return 0;
}
