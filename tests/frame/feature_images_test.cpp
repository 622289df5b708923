#include "toonray/frame/feature_images.h"

#include <gtest/gtest.h>

#include "toonray/core/error.h"

#include <string_view>
#include <vector>

using namespace toonray;

TEST(FeatureImages, TheTableListsEachModesImages) {
    std::vector<std::string_view> classic, robust, ink;
    for (const FeatureImage& f : feature_images()) {
        if (f.in(LineMode::Classic)) classic.push_back(f.name);
        if (f.in(LineMode::Robust)) robust.push_back(f.name);
        if (f.in(LineMode::Ink)) ink.push_back(f.name);
    }
    EXPECT_EQ(ink,
              (std::vector<std::string_view>{
                  "depth", "normal", "edges", "tone", "cel", "lines_silhouette", "lines_crease",
                  "lines_material", "lines_border", "lines_intersection", "lines_polyline",
                  "lines_band", "lines_shadow", "object_id", "material_id", "samples"}));
    EXPECT_EQ(classic, (std::vector<std::string_view>{"depth", "normal", "edges_depth",
                                                      "edges_normal", "edges", "cel"}));
    EXPECT_EQ(robust, (std::vector<std::string_view>{
                          "depth", "normal", "edges", "cel", "lines_silhouette", "lines_crease",
                          "lines_depth", "lines_object", "lines_material", "object_id",
                          "material_id", "samples"}));
}

TEST(FeatureImages, EncodingAFrameWithoutLayersIsAnError) {
    FrameLayers layers;
    layers.mode = LineMode::Ink;
    layers.image.reshape(4, 3);
    FeatureBytes bytes;
    for (const FeatureImage& f : feature_images()) {
        if (!f.in(LineMode::Ink)) continue;
        EXPECT_THROW(f.encode(layers, 1, bytes), Error) << f.name;
    }
}
