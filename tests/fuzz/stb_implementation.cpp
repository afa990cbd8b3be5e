// stb_image and stb_image_write compiled into the image fuzzer (instrumented), in place of the
// system's libstb.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image.h>
#include <stb_image_write.h>
