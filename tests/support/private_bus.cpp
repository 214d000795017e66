#include "support/private_bus.h"

#include <signal.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "support/process.h"

namespace everytouch::test {

namespace {

// The rules of /usr/share/dbus-1/system.conf that matter here: nobody owns or calls anything unless a
// policy file allows it.
constexpr const char* kDefaultDenyPolicy = R"(
  <policy context="default">
    <allow user="*"/>
    <deny own="*"/>
    <deny send_type="method_call"/>
    <allow send_type="signal"/>
    <allow send_requested_reply="true" send_type="method_return"/>
    <allow send_requested_reply="true" send_type="error"/>
    <allow receive_type="method_call"/>
    <allow receive_type="method_return"/>
    <allow receive_type="error"/>
    <allow receive_type="signal"/>
    <allow send_destination="org.freedesktop.DBus" send_interface="org.freedesktop.DBus"/>
    <allow send_destination="org.freedesktop.DBus" send_interface="org.freedesktop.DBus.Introspectable"/>
    <allow send_destination="org.freedesktop.DBus" send_interface="org.freedesktop.DBus.Properties"/>
  </policy>
)";

constexpr const char* kPermissivePolicy = R"(
  <policy context="default">
    <allow user="*"/>
    <allow own="*"/>
    <allow send_destination="*"/>
    <allow receive_sender="*"/>
  </policy>
)";

}  // namespace

PrivateBus::PrivateBus(const std::filesystem::path& policyFile, bool permissive) {
    // Unprivileged clients (setpriv --reuid) must reach the socket.
    std::filesystem::permissions(directory_.path(), std::filesystem::perms(0755));
    const std::filesystem::path config = directory_ / "bus.conf";
    {
        std::ofstream out(config);
        out << "<!DOCTYPE busconfig PUBLIC \"-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN\"\n"
               " \"http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd\">\n"
               "<busconfig>\n  <type>system</type>\n"
            << "  <listen>unix:path=" << (directory_ / "system_bus_socket").string() << "</listen>\n"
            << "  <auth>EXTERNAL</auth>\n"
            << (permissive ? kPermissivePolicy : kDefaultDenyPolicy);
        if (!permissive)
            out << "  <include>" << std::filesystem::absolute(policyFile).string() << "</include>\n";
        out << "</busconfig>\n";
    }
    // --fork with --print-address returns once the socket listens.
    const ProcessResult started = runProcess({"/usr/bin/dbus-daemon", "--config-file=" + config.string(),
                                              "--fork", "--print-address=1", "--print-pid=1"});
    int pid = 0;
    char address[512] = {};
    if (started.exitCode != 0 || std::sscanf(started.out.c_str(), "%511s %d", address, &pid) != 2)
        throw std::runtime_error("dbus-daemon did not start: " + started.err);
    address_ = address;
    pid_ = pid;
    ::setenv("DBUS_SYSTEM_BUS_ADDRESS", address_.c_str(), 1);
}

PrivateBus::~PrivateBus() {
    ::unsetenv("DBUS_SYSTEM_BUS_ADDRESS");
    if (pid_ > 0)
        ::kill(pid_, SIGTERM);
}

}  // namespace everytouch::test
