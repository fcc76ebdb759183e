// The project's one copy of stb_image and stb_image_write (Debian's
// libstb-dev): scene textures decode through decodeImageBytes (image.cpp),
// which checks what stb would trust before calling it.
//
// Compiled apart so that one sanitizer check can be left out here alone
// (src/image/CMakeLists.txt): stb copies zero bytes from a null buffer for an
// empty PNG chunk (memcpy(NULL, p, 0), harmless but formally undefined; a
// finding of the image fuzz target). Everything else of stb stays checked.

#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>
