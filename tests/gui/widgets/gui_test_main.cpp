// GoogleTest main for widget tests: one QApplication for the whole program. Set
// DELINEO_SCREENSHOT_DIR to keep PNG renderings of the widgets for a visual check.
#include <QApplication>
#include <gtest/gtest.h>

#include "delineo/widgets/terrain3d_view.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  delineo::widgets::Terrain3DView::setDefaultSurfaceFormat();
  QApplication app(argc, argv);
  return RUN_ALL_TESTS();
}
