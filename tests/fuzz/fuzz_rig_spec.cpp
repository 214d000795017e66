// The --rig value: parsed, and a simulated rig's options applied as the daemon applies them. Bad text may
// only give io::InputError or the simulator's message; anything else is a finding.
#include <cstdint>
#include <string_view>

#include "io/input_error.h"
#include "io/rig_spec.h"
#include "sim/sim_options.h"
#include "sim/sim_parameters.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace everytouch;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const io::RigSpec spec = io::RigSpec::parse(text);
        // What the daemon prints as the rig it runs must read back as the same rig.
        if (io::RigSpec::parse(spec.toString()).toString() != spec.toString())
            __builtin_trap();
        if (spec.kind == io::RigSpec::Kind::Sim) {
            sim::SimParameters parameters;
            bool applied = true;
            for (const auto& [key, value] : spec.options)
                if (sim::applyOption(parameters, key, value)) {
                    applied = false;
                    break;
                }
            if (applied)
                (void)parameters.validate();
        }
    } catch (const io::InputError&) {
    }
    return 0;
}
