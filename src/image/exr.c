/*
 * exr.c - OpenEXR output and input through OpenEXR's core C API (OpenEXRCore), see exr.h.
 *
 * No EXR coding happens here: OpenEXR builds the header, converts float <-> half,
 * compresses and decompresses. This file only connects OpenEXR's custom-stream hooks to
 * our stream (writing) or our in-memory bytes (reading), walks the chunks of scanlines,
 * and tells OpenEXR where each channel's samples live in the interleaved RGB rows of a
 * rad_image.
 *
 * OpenEXR reports errors through a callback that would otherwise print to stderr; ours
 * keeps the first message (the cause; later ones are consequences) for the one-line error.
 */
#include "image/exr.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <openexr.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "core/error.h"

_Static_assert(sizeof(float) == 4, "EXR float channels are 32-bit");

/* Interleaved RGB floats: the bytes from one pixel to the next in a rad_image row. */
#define PIXEL_BYTES ((int32_t)(3 * sizeof(float)))
/* OpenEXR's dimensions and strides are int32_t: the widest row whose byte stride fits. */
#define EXR_MAX_WIDTH (INT32_MAX / PIXEL_BYTES)
/* Each chunk of scanlines has an 8-byte entry in the offset table after the header. */
#define EXR_OFFSET_ENTRY_BYTES 8

/* What the stream hooks and the error callback share (OpenEXR's "user data"). */
typedef struct exr_stream {
    FILE *file;            /* writing: the open (temporary) file */
    uint64_t position;     /* writing: the file position after the last write */
    const uint8_t *data;   /* reading: the whole file */
    size_t size;           /* reading: its size in bytes */
    char message[256];     /* the first message OpenEXR reported, one line; "" if none */
} exr_stream;

/* ----------------------------------------------------------------------------------- */
/* Errors                                                                              */

static void keep_first_message(exr_const_context_t context, exr_result_t code,
                               const char *message)
{
    void *user = NULL;
    if (exr_get_user_data(context, &user) != EXR_ERR_SUCCESS || !user)
        return;
    exr_stream *stream = user;
    if (stream->message[0])
        return;
    snprintf(stream->message, sizeof(stream->message), "%s",
             message && *message ? message : exr_get_default_error_message(code));
    for (char *c = stream->message; *c; c++)
        if (*c == '\n' || *c == '\r' || *c == '\t')
            *c = ' ';
    size_t length = strlen(stream->message);
    while (length > 0 && stream->message[length - 1] == ' ')
        stream->message[--length] = 0;
}

/* The message for a failed call: the one OpenEXR reported, else the code's default text. */
static const char *message_of(const exr_stream *stream, exr_result_t code)
{
    return stream->message[0] ? stream->message : exr_get_default_error_message(code);
}

/* ----------------------------------------------------------------------------------- */
/* Writing                                                                             */

/* OpenEXR's write hook (pwrite semantics): writes size bytes at offset of our stream. */
static int64_t write_to_stream(exr_const_context_t context, void *user, const void *buffer,
                               uint64_t size, uint64_t offset,
                               exr_stream_error_func_ptr_t error_cb)
{
    exr_stream *stream = user;
    if (offset != stream->position) {
        if (offset > (uint64_t)INT64_MAX ||
            fseeko(stream->file, (off_t)offset, SEEK_SET) != 0) {
            error_cb(context, EXR_ERR_WRITE_IO, "cannot seek: %s", strerror(errno));
            return -1;
        }
        stream->position = offset;
    }
    if (size > (uint64_t)INT64_MAX || fwrite(buffer, 1, size, stream->file) != size) {
        error_cb(context, EXR_ERR_WRITE_IO, "write failed: %s", strerror(errno));
        return -1;
    }
    stream->position += size;
    return (int64_t)size;
}

static rad_status write_status(exr_result_t code)
{
    switch (code) {
    case EXR_ERR_OUT_OF_MEMORY: return RAD_ERR_NOMEM;
    case EXR_ERR_WRITE_IO: return RAD_ERR_IO;
    default: return RAD_ERR_INTERNAL; /* we asked for something OpenEXR refused */
    }
}

/* Encodes every chunk of scanlines of the image into part 0 of context. */
static exr_result_t write_chunks(exr_context_t context, const rad_image *image)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(context, 0, &lines);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    if (lines < 1)
        return EXR_ERR_INVALID_ARGUMENT;
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    int32_t height = (int32_t)image->height, width = (int32_t)image->width;
    bool started = false;
    for (int32_t y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t chunk;
        rv = exr_write_scanline_chunk_info(context, 0, y, &chunk);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_encoding_update(context, 0, &chunk, &encoder)
                     : exr_encoding_initialize(context, 0, &chunk, &encoder);
        if (rv != EXR_ERR_SUCCESS)
            break;
        started = true;
        const float *first_row = image->rgb + (size_t)chunk.start_y * (size_t)width * 3;
        for (int16_t c = 0; c < encoder.channel_count; c++) {
            exr_coding_channel_info_t *channel = &encoder.channels[c];
            const char *name = channel->channel_name;
            size_t offset = name[0] == 'R' ? 0 : name[0] == 'G' ? 1 : 2; /* we made R G B */
            channel->encode_from_ptr = (const uint8_t *)(first_row + offset);
            channel->user_pixel_stride = PIXEL_BYTES;
            channel->user_line_stride = PIXEL_BYTES * width;
            channel->user_bytes_per_element = (int16_t)sizeof(float);
            channel->user_data_type = EXR_PIXEL_FLOAT;
        }
        rv = exr_encoding_choose_default_routines(context, 0, &encoder);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(context, 0, &encoder);
    }
    if (started)
        exr_encoding_destroy(context, &encoder);
    return rv;
}

/* The largest finite half-precision value. */
#define HALF_LARGEST 65504.0f

rad_status rad_exr_write(const rad_image *image, bool float_channels, FILE *stream,
                         const char *path, rad_error *error)
{
    if (image->width > (uint32_t)EXR_MAX_WIDTH || image->height > (uint32_t)INT32_MAX)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "%s: %" PRIu32 " x %" PRIu32 " is too large for an EXR file", path,
                        image->width, image->height);
    exr_stream sink = {.file = stream};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keep_first_message;
    init.user_data = &sink;
    init.write_fn = write_to_stream;

    exr_context_t context = NULL;
    exr_result_t rv = exr_start_write(&context, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&context);
        return rad_fail(error, write_status(rv), "%s: cannot start an EXR file: %s", path,
                        message_of(&sink, rv));
    }
    int part = 0;
    /* half holds at most 65504: brighter images go to float rather than to infinity */
    size_t values = (size_t)image->width * image->height * 3;
    for (size_t k = 0; k < values && !float_channels; k++)
        float_channels = fabsf(image->rgb[k]) > HALF_LARGEST && isfinite(image->rgb[k]);
    exr_pixel_type_t type = float_channels ? EXR_PIXEL_FLOAT : EXR_PIXEL_HALF;
    rv = exr_add_part(context, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(context, part, (int32_t)image->width,
                                                 (int32_t)image->height,
                                                 EXR_COMPRESSION_ZIP);
    const char *names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(context, part, names[c], type, EXR_PERCEPTUALLY_LOGARITHMIC,
                             1, 1); /* radiance, like any RGB; full resolution */
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(context);
    if (rv == EXR_ERR_SUCCESS)
        rv = write_chunks(context, image);
    /* exr_finish writes the chunk offset table and frees the context; after a failure,
     * whatever it writes goes away with the temporary file, which the caller removes. */
    exr_result_t finished = exr_finish(&context);
    if (rv == EXR_ERR_SUCCESS)
        rv = finished;
    if (rv != EXR_ERR_SUCCESS)
        return rad_fail(error, write_status(rv), "%s: cannot write EXR: %s", path,
                        message_of(&sink, rv));
    return RAD_OK;
}

/* ----------------------------------------------------------------------------------- */
/* Reading                                                                             */

/* OpenEXR's read hook (pread semantics): up to size bytes from offset; 0 at the end. */
static int64_t read_from_memory(exr_const_context_t context, void *user, void *buffer,
                                uint64_t size, uint64_t offset,
                                exr_stream_error_func_ptr_t error_cb)
{
    (void)context;
    (void)error_cb;
    const exr_stream *stream = user;
    if (offset >= stream->size)
        return 0;
    uint64_t available = stream->size - offset;
    uint64_t count = size < available ? size : available;
    if (count > (uint64_t)INT64_MAX)
        count = (uint64_t)INT64_MAX;
    memcpy(buffer, stream->data + offset, (size_t)count);
    return (int64_t)count;
}

static int64_t size_of_memory(exr_const_context_t context, void *user)
{
    (void)context;
    const exr_stream *stream = user;
    return stream->size > (size_t)INT64_MAX ? -1 : (int64_t)stream->size;
}

static rad_status read_status(exr_result_t code)
{
    switch (code) {
    case EXR_ERR_OUT_OF_MEMORY: return RAD_ERR_NOMEM;
    case EXR_ERR_FEATURE_NOT_IMPLEMENTED: return RAD_ERR_UNSUPPORTED;
    default: return RAD_ERR_PARSE; /* the bytes are all in memory: the file is at fault */
    }
}

/* Which of the file's channels are read. */
typedef struct channel_map {
    bool grey; /* a lone Y (no R, G, B, RY, BY): decode Y into red, then copy it */
} channel_map;

/* Where a channel of the file goes in a rad_image pixel: 0, 1, 2 for R, G, B (0 for a grey
 * Y), -1 for channels that are skipped. */
static int target_of(const channel_map *map, const char *name)
{
    if (map->grey)
        return strcmp(name, "Y") == 0 ? 0 : -1;
    if (strcmp(name, "R") == 0)
        return 0;
    if (strcmp(name, "G") == 0)
        return 1;
    if (strcmp(name, "B") == 0)
        return 2;
    return -1;
}

/* The colour channels looked for in a file's channel list. */
enum { HAS_R, HAS_G, HAS_B, HAS_Y, HAS_CHROMA, HAS_COUNT };

/* Which of them a channel name is (RY and BY are both chroma); -1 for any other name. */
static int colour_channel(const char *name)
{
    static const char *const names[] = {"R", "G", "B", "Y", "RY", "BY"};
    for (int i = 0; i < (int)(sizeof(names) / sizeof(names[0])); i++)
        if (strcmp(name, names[i]) == 0)
            return i < HAS_CHROMA ? i : HAS_CHROMA;
    return -1;
}

/* Checks the channel list: R, G and B (or a lone Y), full resolution, half or float. */
static rad_status choose_channels(exr_const_context_t context, const char *path,
                                  channel_map *map, rad_error *error)
{
    const exr_attr_chlist_t *list = NULL;
    if (exr_get_channels(context, 0, &list) != EXR_ERR_SUCCESS || !list)
        return rad_fail(error, RAD_ERR_PARSE, "%s: EXR file without a channel list", path);
    bool has[HAS_COUNT] = {false};
    for (int i = 0; i < list->num_channels; i++) {
        int which = colour_channel(list->entries[i].name.str);
        if (which >= 0)
            has[which] = true;
    }
    /* Y with RY and BY is luminance/chroma colour, not grey. */
    map->grey = has[HAS_Y] && !has[HAS_CHROMA] && !has[HAS_R] && !has[HAS_G] && !has[HAS_B];
    if (!map->grey && !(has[HAS_R] && has[HAS_G] && has[HAS_B]))
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "%s: EXR channels are not R, G, B (or Y): only RGB(A) or grey "
                        "images are supported", path);
    for (int i = 0; i < list->num_channels; i++) {
        const exr_attr_chlist_entry_t *entry = &list->entries[i];
        if (target_of(map, entry->name.str) < 0)
            continue;
        if (entry->pixel_type != EXR_PIXEL_HALF && entry->pixel_type != EXR_PIXEL_FLOAT)
            return rad_fail(error, RAD_ERR_UNSUPPORTED,
                            "%s: EXR channel %s holds integers (only half or float is "
                            "supported)", path, entry->name.str);
        if (entry->x_sampling != 1 || entry->y_sampling != 1)
            return rad_fail(error, RAD_ERR_UNSUPPORTED,
                            "%s: EXR channel %s is subsampled (not supported)", path,
                            entry->name.str);
    }
    return RAD_OK;
}

/* Decodes every chunk of part 0 into image, whose pixel 0 is the data window's corner. */
static exr_result_t read_chunks(exr_const_context_t context, const exr_attr_box2i_t *window,
                                const channel_map *map, rad_image *image)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(context, 0, &lines);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    if (lines < 1)
        return EXR_ERR_FILE_BAD_HEADER;
    exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
    bool started = false;
    int32_t width = (int32_t)image->width;
    for (int64_t y = window->min.y; y <= window->max.y && rv == EXR_ERR_SUCCESS;
         y += lines) {
        exr_chunk_info_t chunk;
        rv = exr_read_scanline_chunk_info(context, 0, (int)y, &chunk);
        if (rv != EXR_ERR_SUCCESS)
            break;
        if (chunk.start_y < window->min.y || chunk.height < 1 ||
            (int64_t)chunk.start_y + chunk.height - 1 > window->max.y) {
            rv = EXR_ERR_BAD_CHUNK_LEADER;
            break;
        }
        rv = started ? exr_decoding_update(context, 0, &chunk, &decoder)
                     : exr_decoding_initialize(context, 0, &chunk, &decoder);
        if (rv != EXR_ERR_SUCCESS)
            break;
        started = true;
        size_t top = (size_t)((int64_t)chunk.start_y - window->min.y);
        float *first_row = image->rgb + top * (size_t)width * 3;
        for (int16_t c = 0; c < decoder.channel_count; c++) {
            exr_coding_channel_info_t *channel = &decoder.channels[c];
            int target = target_of(map, channel->channel_name);
            channel->decode_to_ptr = target < 0 ? NULL : (uint8_t *)(first_row + target);
            channel->user_pixel_stride = PIXEL_BYTES;
            channel->user_line_stride = PIXEL_BYTES * width;
            channel->user_bytes_per_element = (int16_t)sizeof(float);
            channel->user_data_type = EXR_PIXEL_FLOAT;
        }
        rv = exr_decoding_choose_default_routines(context, 0, &decoder);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_decoding_run(context, 0, &decoder);
    }
    if (started)
        exr_decoding_destroy(context, &decoder);
    return rv;
}

/* Everything after the header is parsed: the layout checks, then the pixels. */
static rad_status read_part(exr_const_context_t context, exr_stream *source,
                            const char *path, rad_image **out, rad_error *error)
{
    int parts = 0;
    exr_storage_t storage = EXR_STORAGE_SCANLINE;
    if (exr_get_count(context, &parts) != EXR_ERR_SUCCESS || parts < 1 ||
        exr_get_storage(context, 0, &storage) != EXR_ERR_SUCCESS)
        return rad_fail(error, RAD_ERR_PARSE, "%s: EXR file without an image part", path);
    if (parts > 1)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "%s: multi-part EXR files (%d parts) are not supported", path,
                        parts);
    if (storage == EXR_STORAGE_TILED)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "%s: tiled EXR files are not supported (only scanline files)",
                        path);
    if (storage != EXR_STORAGE_SCANLINE)
        return rad_fail(error, RAD_ERR_UNSUPPORTED,
                        "%s: deep EXR files are not supported (only flat scanline files)",
                        path);

    channel_map map = {.grey = false};
    rad_status status = choose_channels(context, path, &map, error);
    if (status != RAD_OK)
        return status;
    exr_attr_box2i_t window;
    int32_t chunks = 0;
    if (exr_get_data_window(context, 0, &window) != EXR_ERR_SUCCESS ||
        exr_get_chunk_count(context, 0, &chunks) != EXR_ERR_SUCCESS)
        return rad_fail(error, RAD_ERR_PARSE, "%s: EXR header without a data window", path);
    int64_t width = (int64_t)window.max.x - window.min.x + 1;
    int64_t height = (int64_t)window.max.y - window.min.y + 1;
    if (width < 1 || height < 1)
        return rad_fail(error, RAD_ERR_PARSE, "%s: EXR data window is empty", path);
    if (width > EXR_MAX_WIDTH)
        return rad_fail(error, RAD_ERR_UNSUPPORTED, "%s: EXR image %" PRId64 " pixels wide "
                        "is too wide", path, width);
    /* The offset table must be present before anything is allocated for the pixels. */
    if (chunks < 1 || (uint64_t)chunks * EXR_OFFSET_ENTRY_BYTES > source->size)
        return rad_fail(error, RAD_ERR_PARSE,
                        "%s: truncated: an EXR file of %" PRId32 " chunks in %zu bytes",
                        path, chunks, source->size);

    rad_image *image = NULL;
    status = rad_image_create((uint32_t)width, (uint32_t)height, &image, error);
    if (status != RAD_OK)
        return status;
    exr_result_t rv = read_chunks(context, &window, &map, image);
    if (rv != EXR_ERR_SUCCESS) {
        rad_image_destroy(image);
        return rad_fail(error, read_status(rv), "%s: bad EXR pixel data: %s", path,
                        message_of(source, rv));
    }
    if (map.grey)
        for (size_t i = 0; i < (size_t)image->width * image->height; i++)
            image->rgb[3 * i + 1] = image->rgb[3 * i + 2] = image->rgb[3 * i];
    *out = image;
    return RAD_OK;
}

rad_status rad_exr_read(const uint8_t *data, size_t size, const char *path, rad_image **out,
                        rad_error *error)
{
    exr_stream source = {.data = data, .size = size};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keep_first_message;
    init.user_data = &source;
    init.read_fn = read_from_memory;
    init.size_fn = size_of_memory;
    /* A damaged offset table is an error, not something to search the file for. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;

    exr_context_t context = NULL;
    exr_result_t rv = exr_start_read(&context, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&context);
        return rad_fail(error, read_status(rv), "%s: bad EXR header: %s", path,
                        message_of(&source, rv));
    }
    rad_status status = read_part(context, &source, path, out, error);
    exr_finish(&context);
    return status;
}
