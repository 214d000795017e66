#pragma once

#include <libevdev/libevdev-uinput.h>
#include <libevdev/libevdev.h>

#include "io/handles.h"

namespace everytouch::io {

// libevdev's handles, apart from io/handles.h so that only what drives the virtual touchscreen needs its
// headers.
using UniqueLibevdev = UniqueHandle<libevdev, libevdev_free>;
// Destroying it removes the uinput device and closes /dev/uinput.
using UniqueLibevdevUinput = UniqueHandle<libevdev_uinput, libevdev_uinput_destroy>;

}  // namespace everytouch::io
