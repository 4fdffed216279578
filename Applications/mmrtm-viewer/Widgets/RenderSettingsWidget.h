// Render settings of the path tracer: samples per render, the stop
// condition (maximum samples or a target relative noise), bounces, shadow
// extinction scale, accelerator, backend, exposure, and the key light
// (direction relative to the camera, intensity) and the environment light.
// Plain Qt.
#pragma once

#include <QWidget>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QSpinBox;

namespace mmrtm::viewer {

struct RenderSettings {
  int samplesPerRender = 1;
  bool stopAtNoise = false;  // stop at noiseTarget, else at maximumSamples
  int maximumSamples = 256;
  double noiseTarget = 0.02;
  int bounces = 32;
  double shadowScale = 0.8;
  int accelerator = 0;  // 0 octree, 1 macrocell, 2 none
  int backend = 0;      // 0 auto, 1 CPU, 2 CUDA
  double exposure = 1.0;
  int denoising = 1;  // what the view shows: 0 the unbiased image, 1 denoised while closer (auto), 2 denoised
  double lightAzimuth = -35, lightElevation = 40, lightIntensity = 3.0;
  bool environment = true;
};

class RenderSettingsWidget : public QWidget {
  Q_OBJECT

 public:
  explicit RenderSettingsWidget(QWidget* parent = nullptr);
  void setSettings(const RenderSettings& settings);
  RenderSettings settings() const;

 signals:
  void settingsChanged();

 private:
  QSpinBox *samplesPerRender_, *maximumSamples_, *bounces_;
  QComboBox *stop_, *accelerator_, *backend_, *denoising_;
  QDoubleSpinBox *noiseTarget_, *shadowScale_, *exposure_, *lightAzimuth_, *lightElevation_, *lightIntensity_;
  QCheckBox* environment_;
  bool filling_ = false;
};

}  // namespace mmrtm::viewer
