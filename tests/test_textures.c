/*
 * test_textures.c - albedo textures (MTL map_Kd, glTF baseColorTexture), PNG and JPEG:
 *   - a patch's albedo is Kd times the texture's mean over it: 0.5 Kd for a black-and-white
 *     texture under one patch (exact by symmetry of the bilinear samples), a JPEG's grey
 *     decoded from sRGB;
 *   - which way up: OBJ's v and glTF's (flipped) v put the same texel on the same half,
 *     with the image in a file or inside a .glb;
 *   - the render keeps detail finer than the patches: a floor lit only directly (the lamp
 *     reflects nothing) gets the same irradiance whatever its albedo, so a textured floor
 *     shows texel / 0.5 times the image of a uniform 0.5 floor: 0 on its black half and 2
 *     on its white half, though its patches straddle both.
 */
#include <math.h>
#include <png.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h> /* after stdio.h: it uses FILE and size_t */

#include "testlib.h"

static void write_grey_jpeg(const char *name, unsigned value)
{
    FILE *file = fopen(test_path(name), "wb");
    if (!file) {
        test_fail(__FILE__, __LINE__, "cannot write %s", name);
        return;
    }
    struct jpeg_compress_struct info;
    struct jpeg_error_mgr errors;
    info.err = jpeg_std_error(&errors);
    jpeg_create_compress(&info);
    jpeg_stdio_dest(&info, file);
    info.image_width = 16;
    info.image_height = 16;
    info.input_components = 3;
    info.in_color_space = JCS_RGB;
    jpeg_set_defaults(&info);
    jpeg_set_quality(&info, 100, TRUE);
    jpeg_start_compress(&info, TRUE);
    unsigned char row[16 * 3];
    memset(row, (int)value, sizeof(row));
    while (info.next_scanline < 16) {
        JSAMPROW rows[1] = {row};
        jpeg_write_scanlines(&info, rows, 1);
    }
    jpeg_finish_compress(&info);
    jpeg_destroy_compress(&info);
    fclose(file);
}

/* The floor [0,2] x [0,2] at y = 0 facing up, u along x and v along z, with `material`. */
static const char *floor_obj(const char *mtl, const char *material, bool lamp)
{
    static char text[2048];
    snprintf(text, sizeof(text),
             "mtllib %s\n"
             "o floor\nusemtl %s\n"
             "v 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 0 0\n"
             "vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n"
             "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
             "%s",
             mtl, material,
             lamp ? "o lamp\nusemtl lamp\nv -0.5 0 0\nv -0.5 1 0\nv -0.5 1 2\nv -0.5 0 2\n"
                    "f 5 6 7\nf 5 7 8\n"
                  : "");
    return text;
}

/* The patch albedos of the floor, meshed at patch_size; returns the patch count. */
static uint32_t floor_albedo(const char *name, double patch_size, rad_rgb *albedo,
                             rad_vec3 *centroid, uint32_t capacity)
{
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_error error;
    uint32_t count = 0;
    if (rad_scene_load(test_path(name), NULL, &scene, &error) != RAD_OK ||
        rad_mesh_build(scene, patch_size, &mesh, &error) != RAD_OK) {
        test_fail(__FILE__, __LINE__, "%s: %s", name, error.message);
    } else {
        CHECK(scene->texture_count == 1);
        rad_rgb *all = calloc(mesh->patch_count, sizeof(*all));
        CHECK(all && rad_patch_materials(scene, mesh, all, NULL, &error) == RAD_OK);
        for (uint32_t p = 0; all && p < mesh->patch_count && count < capacity; p++)
            if (mesh->patches[p].normal.y > 0.5) {
                albedo[count] = all[p];
                centroid[count++] = mesh->patches[p].centroid;
            }
        free(all);
    }
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return count;
}

static void patch_averages(void)
{
    /* 2 x 1: black | white */
    const unsigned char stripes[6] = {0, 0, 0, 255, 255, 255};
    test_write_png("stripes.png", 2, 1, stripes);
    test_write_file("stripes.mtl", "newmtl striped\nKd 1 0.5 0.25\nmap_Kd stripes.png\n");
    test_write_file("stripes.obj", floor_obj("stripes.mtl", "striped", false));
    rad_rgb albedo[16];
    rad_vec3 centroid[16];
    CHECK(floor_albedo("stripes.obj", 10, albedo, centroid, 16) == 1);
    CHECK_NEAR(albedo[0].r, 0.5, 1e-6);
    CHECK_NEAR(albedo[0].g, 0.25, 1e-6);
    CHECK_NEAR(albedo[0].b, 0.125, 1e-6);

    /* a JPEG of sRGB 128 everywhere: albedo = Kd x 0.2158 */
    write_grey_jpeg("grey.jpg", 128);
    test_write_file("grey.mtl", "newmtl grey\nKd 1 1 1\nmap_Kd grey.jpg\n");
    test_write_file("grey.obj", floor_obj("grey.mtl", "grey", false));
    CHECK(floor_albedo("grey.obj", 10, albedo, centroid, 16) == 1);
    CHECK_NEAR(albedo[0].g, test_srgb_to_linear(128), 0.02);
}

/* 1 x 2: white on top (v = 1 end), black below. OBJ's v and glTF's v (1 - OBJ's) must both
 * put white on the z > 1 half of the floor. */
static void which_way_up(void)
{
    const unsigned char rows[6] = {255, 255, 255, 0, 0, 0};
    test_write_png("updown.png", 1, 2, rows);
    test_write_file("updown.mtl", "newmtl updown\nKd 1 1 1\nmap_Kd updown.png\n");
    test_write_file("updown.obj", floor_obj("updown.mtl", "updown", false));
    /* the same floor as glTF: positions, glTF texture coordinates (v down), indices */
    float data[4 * 3 + 4 * 2] = {0, 0, 0, 0, 0, 2, 2, 0, 2, 2, 0, 0,
                                 0, 1, 0, 0, 1, 0, 1, 1};
    uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    FILE *file = fopen(test_path("updown.bin"), "wb");
    if (file) {
        fwrite(data, sizeof(data), 1, file);
        fwrite(indices, sizeof(indices), 1, file);
        fclose(file);
    }
    test_write_file(
        "updown.gltf",
        "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"name\":\"floor\",\"primitives\":[{\"attributes\":{\"POSITION\":0,"
        "\"TEXCOORD_0\":1},\"indices\":2,\"material\":0}]}],"
        "\"materials\":[{\"name\":\"updown\",\"pbrMetallicRoughness\":{\"baseColorTexture\":"
        "{\"index\":0}}}],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"updown.png\"}],"
        "\"buffers\":[{\"byteLength\":92,\"uri\":\"updown.bin\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,"
        "\"byteLength\":32},{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[2,0,2]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,"
        "\"type\":\"VEC2\"},{\"bufferView\":2,\"componentType\":5123,\"count\":6,"
        "\"type\":\"SCALAR\"}]}");
    /* and as a .glb that embeds the PNG in its binary chunk */
    unsigned char png[1024];
    size_t png_size = 0;
    FILE *png_file = fopen(test_path("updown.png"), "rb");
    if (png_file) {
        png_size = fread(png, 1, sizeof(png), png_file);
        fclose(png_file);
    }
    char json[4096];
    int json_size = snprintf(
        json, sizeof(json),
        "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"name\":\"floor\",\"primitives\":[{\"attributes\":{\"POSITION\":0,"
        "\"TEXCOORD_0\":1},\"indices\":2,\"material\":0}]}],"
        "\"materials\":[{\"name\":\"updown\",\"pbrMetallicRoughness\":{\"baseColorTexture\":"
        "{\"index\":0}}}],\"textures\":[{\"source\":0}],"
        "\"images\":[{\"bufferView\":3,\"mimeType\":\"image/png\"}],"
        "\"buffers\":[{\"byteLength\":%zu}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,"
        "\"byteLength\":32},{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12},"
        "{\"buffer\":0,\"byteOffset\":92,\"byteLength\":%zu}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[2,0,2]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,"
        "\"type\":\"VEC2\"},{\"bufferView\":2,\"componentType\":5123,\"count\":6,"
        "\"type\":\"SCALAR\"}]}",
        92 + png_size, png_size);
    while (json_size % 4)
        json[json_size++] = ' ';
    size_t bin_size = (92 + png_size + 3) & ~(size_t)3;
    FILE *glb = fopen(test_path("updown.glb"), "wb");
    if (glb && png_size > 0) {
        uint32_t header[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + json_size + 8 + bin_size),
                              (uint32_t)json_size, 0x4E4F534Au};
        uint32_t bin_header[2] = {(uint32_t)bin_size, 0x004E4942u};
        unsigned char zero[4] = {0, 0, 0, 0};
        fwrite(header, 4, 5, glb); /* little-endian, as every machine this builds on */
        fwrite(json, 1, (size_t)json_size, glb);
        fwrite(bin_header, 4, 2, glb);
        fwrite(data, sizeof(data), 1, glb);
        fwrite(indices, sizeof(indices), 1, glb);
        fwrite(png, 1, png_size, glb);
        fwrite(zero, 1, bin_size - 92 - png_size, glb);
    }
    if (glb)
        fclose(glb);
    const char *names[3] = {"updown.obj", "updown.gltf", "updown.glb"};
    for (int k = 0; k < 3; k++) {
        rad_rgb albedo[16];
        rad_vec3 centroid[16];
        uint32_t n = floor_albedo(names[k], 1, albedo, centroid, 16);
        CHECK(n == 4);
        double top = 0, bottom = 0;
        for (uint32_t p = 0; p < n; p++)
            *(centroid[p].z > 1 ? &top : &bottom) += albedo[p].g / 2;
        if (!(top > 0.6 && bottom < 0.4))
            fprintf(stderr, "%s: top %.4f bottom %.4f\n", names[k], top, bottom);
        CHECK(top > 0.6 && bottom < 0.4);
        /* the two halves still average to the texture's mean, 0.5 */
        CHECK_NEAR((top + bottom) / 2, 0.5, 1e-6);
    }
}

static rad_image *read_image(const char *name)
{
    rad_image *image = NULL;
    rad_error error;
    if (rad_image_read(test_path(name), &image, &error) != RAD_OK)
        test_fail(__FILE__, __LINE__, "%s", error.message);
    return image;
}

static void render_keeps_detail(void)
{
    test_write_file("plain.mtl", "newmtl plain\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
    test_write_file("plain.obj", floor_obj("plain.mtl", "plain", true));
    test_write_file("lit.mtl", "newmtl striped\nKd 1 1 1\nmap_Kd stripes.png\n"
                               "newmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
    test_write_file("lit.obj", floor_obj("lit.mtl", "striped", true));
    /* looking straight down on the floor, which fills the image's width exactly */
    const char *view = "--size 64x64 --eye 1,10,1 --target 1,0,1 --up 0,0,1 "
                       "--fov 11.4212 --patch-size 0.7";
    char arguments[512];
    snprintf(arguments, sizeof(arguments), "render plain.obj -o plain.pfm %s", view);
    CHECK(test_run_tool(arguments) == 0);
    snprintf(arguments, sizeof(arguments), "render lit.obj -o lit.pfm %s", view);
    CHECK(test_run_tool(arguments) == 0);
    rad_image *plain = read_image("plain.pfm"), *lit = read_image("lit.pfm");
    if (plain && lit) {
        /* columns 14 and 49 lie inside the two texels' halves, mirror images of each other */
        double ratio[2];
        const uint32_t columns[2] = {14, 49};
        for (int k = 0; k < 2; k++) {
            double a = 0, b = 0;
            for (uint32_t y = 24; y < 40; y++) {
                a += test_pixel(lit, columns[k], y)[1];
                b += test_pixel(plain, columns[k], y)[1];
            }
            CHECK(b > 0);
            ratio[k] = a / b;
        }
        printf("textured / uniform: %.4f and %.4f\n", ratio[0], ratio[1]);
        CHECK(fmin(ratio[0], ratio[1]) < 0.15);
        CHECK(fmax(ratio[0], ratio[1]) > 1.85 && fmax(ratio[0], ratio[1]) < 2.0001);
    }
    rad_image_destroy(plain);
    rad_image_destroy(lit);
}

int main(void)
{
    test_tmpdir();
    patch_averages();
    which_way_up();
    render_keeps_detail();
    return test_finish("test_textures");
}
