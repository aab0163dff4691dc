#pragma once
// Table of the document's buildings: id, status, vertex count, roof height, energy, the method
// that produced the outline, and the id of an imported outline in its source.
#include <QAbstractTableModel>

#include "delineo/project/project.hpp"

namespace delineo::gui {

class Document;

class BuildingsModel : public QAbstractTableModel {
  Q_OBJECT
 public:
  enum Column { Id, Status, Vertices, RoofHeight, Energy, Method, SourceId, ColumnCount };
  static constexpr int kIdRole = Qt::UserRole + 1;

  explicit BuildingsModel(QObject* parent = nullptr);
  void setDocument(Document* document);

  int rowCount(const QModelIndex& parent = {}) const override;
  int columnCount(const QModelIndex& parent = {}) const override;
  QVariant data(const QModelIndex& index, int role) const override;
  QVariant headerData(int section, Qt::Orientation orientation, int role) const override;

  // Whether a building has a source id (the view shows the Source id column only then).
  bool hasSourceIds() const;
  int idAt(int row) const;
  int rowOf(int id) const;  // -1 when absent
  static QString statusText(project::BuildingStatus status);
  // The method that produced the building's outline, in words; empty while it has none.
  static QString methodText(const project::Building& building);
  // The energy and its terms, one per line (the energy column's tooltip).
  static QString energyTermsText(const project::Building& building);

 private:
  Document* document_ = nullptr;
};

}  // namespace delineo::gui
