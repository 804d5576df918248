/*
 * scene_generator.c - writes a closed box whose six inward faces are each a g x g grid of
 * quads split in two (12 g^2 triangles), as OBJ + MTL and as binary glTF (.glb), for
 * bench/load. The ceiling emits; the walls are grey.
 *
 * usage: scene_generator TRIANGLES FOLDER   (writes FOLDER/box-TRIANGLES.obj/.mtl/.glb)
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Face f's corner origin and two edge vectors (unit box, front inward). */
static const double faces[6][3][3] = {
    {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}}, /* floor, +y */
    {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}, /* ceiling, -y */
    {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}}, /* left, +x */
    {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}}, /* right, -x */
    {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}}, /* back, -z */
    {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, /* front, +z */
};
static const char *names[6] = {"floor", "ceiling", "left", "right", "back", "front"};

static void point(int f, int g, int i, int j, float out[3])
{
    for (int a = 0; a < 3; a++)
        out[a] = (float)(faces[f][0][a] + faces[f][1][a] * i / g + faces[f][2][a] * j / g);
}

static void put_u32(FILE *file, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    fwrite(b, 1, 4, file);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: scene_generator TRIANGLES FOLDER\n");
        return 2;
    }
    long wanted = strtol(argv[1], NULL, 10);
    int g = 1;
    while (12L * (g + 1) * (g + 1) <= wanted)
        g++;
    long vertices = (long)(g + 1) * (g + 1), quads = (long)g * g;
    char path[4096];

    snprintf(path, sizeof(path), "%s/box-%s.mtl", argv[2], argv[1]);
    FILE *mtl = fopen(path, "w");
    snprintf(path, sizeof(path), "%s/box-%s.obj", argv[2], argv[1]);
    FILE *obj = fopen(path, "w");
    if (!mtl || !obj)
        return 1;
    fprintf(mtl, "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.2 0.2 0.2\nKe 4 4 4\n");
    fprintf(obj, "mtllib box-%s.mtl\n", argv[1]);
    for (int f = 0; f < 6; f++) {
        fprintf(obj, "o %s\nusemtl %s\n", names[f], f == 1 ? "lamp" : "grey");
        for (int i = 0; i <= g; i++)
            for (int j = 0; j <= g; j++) {
                float p[3];
                point(f, g, i, j, p);
                fprintf(obj, "v %.7g %.7g %.7g\n", p[0], p[1], p[2]);
            }
        long base = f * vertices + 1;
        for (int i = 0; i < g; i++)
            for (int j = 0; j < g; j++) {
                long a = base + (long)i * (g + 1) + j, b = a + g + 1, c = b + 1, d = a + 1;
                fprintf(obj, "f %ld %ld %ld\nf %ld %ld %ld\n", a, b, c, a, c, d);
            }
    }
    fclose(obj);
    fclose(mtl);

    /* glb: per face, positions (float x3) then indices (uint32 x3 per triangle) */
    size_t position_bytes = (size_t)vertices * 12, index_bytes = (size_t)quads * 6 * 4;
    size_t face_bytes = position_bytes + index_bytes, bin_bytes = 6 * face_bytes;
    char *json = malloc(65536);
    if (!json)
        return 1;
    size_t n = 0;
#define ADD(...) n += (size_t)snprintf(json + n, 65536 - n, __VA_ARGS__)
    ADD("{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3,4,5]}],"
        "\"nodes\":[");
    for (int f = 0; f < 6; f++)
        ADD("%s{\"mesh\":%d}", f ? "," : "", f);
    ADD("],\"meshes\":[");
    for (int f = 0; f < 6; f++)
        ADD("%s{\"name\":\"%s\",\"primitives\":[{\"attributes\":{\"POSITION\":%d},"
            "\"indices\":%d,\"material\":%d}]}",
            f ? "," : "", names[f], 2 * f, 2 * f + 1, f == 1 ? 1 : 0);
    ADD("],\"materials\":[{\"name\":\"grey\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
        "[0.5,0.5,0.5,1]}},{\"name\":\"lamp\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
        "[0.2,0.2,0.2,1]},\"emissiveFactor\":[1,1,1],\"extensions\":"
        "{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}}],");
    ADD("\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[", bin_bytes);
    for (int f = 0; f < 6; f++)
        ADD("%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
            "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}",
            f ? "," : "", f * face_bytes, position_bytes, f * face_bytes + position_bytes,
            index_bytes);
    ADD("],\"accessors\":[");
    for (int f = 0; f < 6; f++) {
        float lo[3], hi[3];
        point(f, g, 0, 0, lo);
        point(f, g, g, g, hi);
        for (int a = 0; a < 3; a++)
            if (lo[a] > hi[a]) {
                float t = lo[a];
                lo[a] = hi[a];
                hi[a] = t;
            }
        ADD("%s{\"bufferView\":%d,\"componentType\":5126,\"count\":%ld,\"type\":\"VEC3\","
            "\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},"
            "{\"bufferView\":%d,\"componentType\":5125,\"count\":%ld,\"type\":\"SCALAR\"}",
            f ? "," : "", 2 * f, vertices, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], 2 * f + 1,
            quads * 6);
    }
    ADD("]}");
#undef ADD
    while (n % 4)
        json[n++] = ' ';
    snprintf(path, sizeof(path), "%s/box-%s.glb", argv[2], argv[1]);
    FILE *glb = fopen(path, "wb");
    if (!glb)
        return 1;
    put_u32(glb, 0x46546C67u);
    put_u32(glb, 2);
    put_u32(glb, (uint32_t)(12 + 8 + n + 8 + bin_bytes));
    put_u32(glb, (uint32_t)n);
    put_u32(glb, 0x4E4F534Au);
    fwrite(json, 1, n, glb);
    put_u32(glb, (uint32_t)bin_bytes);
    put_u32(glb, 0x004E4942u);
    for (int f = 0; f < 6; f++) {
        for (int i = 0; i <= g; i++)
            for (int j = 0; j <= g; j++) {
                float p[3];
                point(f, g, i, j, p);
                fwrite(p, 4, 3, glb);
            }
        for (int i = 0; i < g; i++)
            for (int j = 0; j < g; j++) {
                uint32_t a = (uint32_t)(i * (g + 1) + j), b = a + (uint32_t)g + 1, c = b + 1,
                         d = a + 1;
                uint32_t tri[6] = {a, b, c, a, c, d};
                for (int k = 0; k < 6; k++)
                    put_u32(glb, tri[k]);
            }
    }
    fclose(glb);
    free(json);
    printf("%ld\n", 12L * g * g);
    return 0;
}
