#include "contacts_view.h"

#include <string>

#include "text_format.h"

namespace everytouch::calib {

namespace {

std::string countOf(std::size_t contacts) {
    return std::to_string(contacts) + (contacts == 1 ? " contact" : " contacts");
}

// "#3 (812, 404) touching" or "#4 (900, 380) hover 12 mm".
std::string describeContact(const ContactReading& contact) {
    const std::string text = format("#%u (%.0f, %.0f)", contact.id, contact.x, contact.y);
    return text + (contact.touching ? " touching" : format(" hover %.0f mm", contact.heightMm));
}

}  // namespace

void ContactsView::show(const DaemonClient::ContactsUpdate& update) {
    contactsSeen_ = contactsSeen_ || update.contactsChanged;
    const std::string seconds = format("%.3f s", update.seconds);
    const std::string frameRate = format("%.1f frames/s", update.frameRate);
    if (!terminal_) {
        if (!update.contactsChanged)
            return;
        std::string line = seconds + "  " + countOf(update.contacts.size());
        for (const ContactReading& contact : update.contacts)
            line += "  " + describeContact(contact);
        std::fprintf(out_, "%s   %s\n", line.c_str(), frameRate.c_str());
        std::fflush(out_);
        return;
    }
    std::string block =
        seconds + "  " +
        (contactsSeen_ ? countOf(update.contacts.size()) : "waiting for a change of contacts") + "   " +
        frameRate + "\n";
    for (const ContactReading& contact : update.contacts)
        block += "  " + describeContact(contact) + "\n";
    // Back to the block's first line, clear to the end of the screen, draw it again.
    if (shownLines_ > 0)
        std::fprintf(out_, "\033[%dA", shownLines_);
    std::fprintf(out_, "\r\033[J%s", block.c_str());
    std::fflush(out_);
    shownLines_ = 1 + static_cast<int>(update.contacts.size());
}

}  // namespace everytouch::calib
