#include "support/bus_commands.h"

#include "service/bus_names.h"

namespace everytouch::test {

std::vector<std::string> concat(std::vector<std::string> first, const std::vector<std::string>& second) {
    first.insert(first.end(), second.begin(), second.end());
    return first;
}

std::vector<std::string> busctl(const std::vector<std::string>& arguments) {
    return concat({"/usr/bin/busctl", "--system", "--no-pager"}, arguments);
}

std::vector<std::string> property(const std::string& verb, const std::string& name) {
    return busctl({verb, bus::kBusName, bus::kObjectPath, bus::kInterface, name});
}

std::vector<std::string> call(const std::string& method, const std::vector<std::string>& arguments) {
    return concat(busctl({"call", bus::kBusName, bus::kObjectPath, bus::kInterface, method}), arguments);
}

}  // namespace everytouch::test
