#pragma once

#include <cstdio>

#include "daemon_client.h"

namespace everytouch::calib {

// What `everytouch-calib monitor` prints. Elsewhere than on a terminal (a pipe, a log) one line per change
// of contacts: "12.345 s  2 contacts  #3 (812, 404) touching  #4 (900, 380) hover 12 mm   118.9 frames/s".
// On a terminal a block redrawn in place: that line's time, count and frame rate, then a contact a line; it
// also follows the frame rate while the contacts stay the same.
class ContactsView {
public:
    ContactsView(std::FILE* out, bool terminal) : out_(out), terminal_(terminal) {}

    void show(const DaemonClient::ContactsUpdate& update);

private:
    std::FILE* out_;
    bool terminal_;
    bool contactsSeen_ = false;  // a Contacts signal came; until then the contacts are unknown
    int shownLines_ = 0;         // the lines of the block on the terminal
};

}  // namespace everytouch::calib
