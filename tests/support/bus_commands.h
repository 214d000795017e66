#pragma once

#include <string>
#include <vector>

namespace everytouch::test {

// Command lines for talking to everytouchd on the system bus the way a user does, with busctl.
std::vector<std::string> concat(std::vector<std::string> first, const std::vector<std::string>& second);
std::vector<std::string> busctl(const std::vector<std::string>& arguments);
// busctl get-property / set-property (`verb`) of the daemon's property `name`.
std::vector<std::string> property(const std::string& verb, const std::string& name);
// busctl call of the daemon's `method`.
std::vector<std::string> call(const std::string& method, const std::vector<std::string>& arguments = {});

}  // namespace everytouch::test
