#pragma once

#include <SDL.h>

#include "io/handles.h"

namespace everytouch::io {

// SDL's windows, renderers and textures (the projector window).
using SdlWindow = UniqueHandle<SDL_Window, SDL_DestroyWindow>;
using SdlRenderer = UniqueHandle<SDL_Renderer, SDL_DestroyRenderer>;
using SdlTexture = UniqueHandle<SDL_Texture, SDL_DestroyTexture>;

}  // namespace everytouch::io
