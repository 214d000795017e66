// The calibration file (/var/lib/everytouch/calibration.yml), read as everytouchd reads it at start and on
// reload. Bad text may only give io::InputError; anything else is a finding.
#include <cstdint>

#include "fuzz_input.h"
#include "io/calibration_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    fuzz::readAsFile("calibration.yml", data, size,
                     [](const std::filesystem::path& path) { (void)io::readCalibrationFile(path); });
    return 0;
}
