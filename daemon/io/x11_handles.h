#pragma once

#include <X11/Xlib.h>

#include "io/handles.h"

namespace everytouch::io {

// An X server connection; closing it frees every resource the connection made on the server (windows,
// pixmaps, colormaps, graphics contexts), so those need no owners of their own.
using XDisplay = UniqueHandle<Display, XCloseDisplay>;

}  // namespace everytouch::io
