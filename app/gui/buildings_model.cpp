#include "buildings_model.hpp"

#include <QBrush>
#include <QColor>
#include <algorithm>
#include <cmath>

#include "document.hpp"

namespace delineo::gui {

using project::BuildingStatus;

BuildingsModel::BuildingsModel(QObject* parent) : QAbstractTableModel(parent) {}

void BuildingsModel::setDocument(Document* document) {
  beginResetModel();
  if (document_ != nullptr) disconnect(document_, nullptr, this, nullptr);
  document_ = document;
  if (document_ != nullptr) {
    // Buildings are few (tens to hundreds): a reset per change keeps the model simple, and the
    // view keeps its selection through the selection model logic of the main window.
    connect(document_, &Document::buildingChanged, this, [this] {
      beginResetModel();
      endResetModel();
    });
    connect(document_, &Document::buildingsReset, this, [this] {
      beginResetModel();
      endResetModel();
    });
  }
  endResetModel();
}

int BuildingsModel::rowCount(const QModelIndex& parent) const {
  if (parent.isValid() || document_ == nullptr) return 0;
  return static_cast<int>(document_->project().buildings.size());
}

int BuildingsModel::columnCount(const QModelIndex& parent) const {
  return parent.isValid() ? 0 : ColumnCount;
}

QString BuildingsModel::statusText(BuildingStatus status) {
  switch (status) {
    case BuildingStatus::Pending: return tr("pending");
    case BuildingStatus::Automatic: return tr("automatic");
    case BuildingStatus::Corrected: return tr("corrected");
    case BuildingStatus::Accepted: return tr("accepted");
    case BuildingStatus::Rejected: return tr("rejected");
  }
  return {};
}

QString BuildingsModel::methodText(const project::Building& building) {
  if (!building.hasOutline()) return {};
  if (building.method == project::kBoxFitting) return tr("box-fitting");
  // Outlines from before methods were recorded came from the active polygon.
  return tr("active polygon");
}

QVariant BuildingsModel::data(const QModelIndex& index, int role) const {
  if (!index.isValid() || document_ == nullptr || index.row() >= rowCount()) return {};
  const auto& b = document_->project().buildings[static_cast<size_t>(index.row())];
  if (role == kIdRole) return b.id;
  if (role == Qt::TextAlignmentRole && index.column() != Status && index.column() != Method &&
      index.column() != SourceId) {
    return QVariant::fromValue(Qt::AlignRight | Qt::AlignVCenter);
  }
  if (role == Qt::ForegroundRole && index.column() == Status) {
    switch (b.status) {
      case BuildingStatus::Accepted: return QBrush(QColor(0, 120, 60));
      case BuildingStatus::Rejected: return QBrush(QColor(170, 40, 40));
      case BuildingStatus::Corrected: return QBrush(QColor(180, 100, 0));
      default: return {};
    }
  }
  if (role == Qt::ToolTipRole && index.column() == Energy) return energyTermsText(b);
  // The source id of an imported outline on the whole row: its column may be scrolled off.
  if (role == Qt::ToolTipRole && !b.sourceId.empty()) return tr("Source id: %1").arg(QString::fromStdString(b.sourceId));
  if (role != Qt::DisplayRole) return {};
  switch (index.column()) {
    case Id: return b.id;
    case Status: return statusText(b.status);
    case Vertices: {
      const auto& poly = b.currentPolygon();
      int n = static_cast<int>(poly.outer.size());
      for (const auto& h : poly.holes) n += static_cast<int>(h.size());
      return n;
    }
    case RoofHeight:
      return std::isfinite(b.roofHeight) ? QVariant(QString::number(b.roofHeight, 'f', 1)) : QVariant(QStringLiteral("–"));
    case Energy:
      return std::isfinite(b.energy) ? QVariant(QString::number(b.energy, 'f', 1)) : QVariant(QStringLiteral("–"));
    case Method: return methodText(b);
    case SourceId: return QString::fromStdString(b.sourceId);
    default: return {};
  }
}

QString BuildingsModel::energyTermsText(const project::Building& b) {
  if (!b.energyTerms) {
    return b.hasOutline() ? tr("Energy F(C) of the outline: being computed, or not computable") : QString();
  }
  const QStringList names = {tr("roof"), tr("ground"), tr("occlusion"), tr("left edges"), tr("right edges"),
                             tr("shape")};
  QStringList lines{tr("Energy F(C) = %1, of which:").arg(b.energy, 0, 'f', 1)};
  for (int t = 0; t < names.size(); ++t) {
    lines << QStringLiteral("  %1  %2").arg(names[t], -12).arg((*b.energyTerms)[static_cast<size_t>(t)], 0, 'f', 1);
  }
  return lines.join(QLatin1Char('\n'));
}

QVariant BuildingsModel::headerData(int section, Qt::Orientation orientation, int role) const {
  if (orientation != Qt::Horizontal || role != Qt::DisplayRole) return {};
  switch (section) {
    case Id: return tr("Id");
    case Status: return tr("Status");
    case Vertices: return tr("Vertices");
    case RoofHeight: return tr("Roof height (m)");
    case Energy: return tr("Energy");
    case Method: return tr("Method");
    case SourceId: return tr("Source id");
    default: return {};
  }
}

bool BuildingsModel::hasSourceIds() const {
  if (document_ == nullptr) return false;
  const auto& list = document_->project().buildings;
  return std::any_of(list.begin(), list.end(), [](const project::Building& b) { return !b.sourceId.empty(); });
}

int BuildingsModel::idAt(int row) const {
  if (document_ == nullptr || row < 0 || row >= rowCount()) return -1;
  return document_->project().buildings[static_cast<size_t>(row)].id;
}

int BuildingsModel::rowOf(int id) const {
  if (document_ == nullptr) return -1;
  const auto& list = document_->project().buildings;
  for (size_t i = 0; i < list.size(); ++i) {
    if (list[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace delineo::gui
