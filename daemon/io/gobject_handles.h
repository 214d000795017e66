#pragma once

#include <glib-object.h>

#include "io/handles.h"

namespace everytouch::io {

// GLib's reference-counted objects (Aravis's cameras, streams and buffers) and its errors.
template <typename T>
using GObjectHandle = UniqueHandle<T, g_object_unref>;
using GErrorHandle = UniqueHandle<GError, g_error_free>;

}  // namespace everytouch::io
