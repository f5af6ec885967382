#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMimeData>
#include <QPushButton>
#include <QScrollArea>
#include <QSpinBox>
#include <QTableWidget>
#include <QTimer>
#include <QToolButton>
#include <QVBoxLayout>
#include <cmath>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "canvas.hpp"
#include "panels.hpp"
#include "qt_text.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor::gui {

// ---- Properties --------------------------------------------------------------------------

PropertiesPanel::PropertiesPanel(QWidget* parent)
    : QWidget(parent), layout_(new QVBoxLayout(this)) {
  layout_->setContentsMargins(0, 0, 0, 0);
  clear();
}

// The old body goes later: show() runs from the signals of its own widgets (an edit is applied,
// the window refreshes), and a widget must not be deleted inside its own signal.
static void dropLater(QWidget*& body) {
  if (body == nullptr) return;
  body->hide();
  body->setParent(nullptr);
  body->deleteLater();
  body = nullptr;
}

void PropertiesPanel::clear() {
  dropLater(body_);
  body_ = new QWidget;
  auto* scroll = new QScrollArea;
  scroll->setWidgetResizable(true);
  scroll->setWidget(new QLabel("  Select a node to edit its properties."));
  auto* l = new QVBoxLayout(body_);
  l->setContentsMargins(0, 0, 0, 0);
  l->addWidget(scroll);
  layout_->addWidget(body_);
}

QWidget* PropertiesPanel::parameterWidget(const QString& name) const {
  return body_ == nullptr ? nullptr : body_->findChild<QWidget*>("param:" + name);
}

QWidget* PropertiesPanel::initialMessagesWidget(const QString& port) const {
  return body_ == nullptr ? nullptr : body_->findChild<QWidget*>("initial:" + port);
}

QWidget* PropertiesPanel::editorFor(const app::ParamSpec& spec, const std::string& value,
                                    bool set) {
  const std::string node = node_;
  const std::string name = spec.name;
  const std::string shown = set ? value : spec.defaultValue;
  const bool numeric = spec.type == app::ParamType::Int || spec.type == app::ParamType::Float ||
                       spec.type == app::ParamType::Vec3;
  // A widget left without a change (focus passing through) must not write the value it shows:
  // an unset parameter would become set to its default, "1e-3" would become "0.001".
  auto emitValue = [this, node, name, shown, numeric](const std::string& v) {
    if (v == shown) return;
    if (numeric) {
      std::istringstream a(v), b(shown);
      double x = 0, y = 0;
      bool same = true, any = false;
      while (a >> x) {
        if (!(b >> y) || x != y) same = false;
        any = true;
      }
      if (any && same && !(b >> y)) return;
    }
    Q_EMIT parameterEdited(node, name, v);
  };
  QWidget* widget = nullptr;
  switch (spec.type) {
    case app::ParamType::Int: {
      auto* box = new QSpinBox;
      const double lo = spec.min.value_or(-1e9), hi = spec.max.value_or(1e9);
      box->setRange(static_cast<int>(std::max(lo, -2147483647.0)),
                    static_cast<int>(std::min(hi, 2147483647.0)));
      box->setValue(static_cast<int>(std::strtoll(shown.c_str(), nullptr, 10)));
      box->setKeyboardTracking(false);
      connect(box, &QSpinBox::editingFinished, this,
              [box, emitValue] { emitValue(std::to_string(box->value())); });
      widget = box;
      break;
    }
    case app::ParamType::Float: {
      auto* box = new QDoubleSpinBox;
      box->setDecimals(6);
      box->setRange(spec.min.value_or(-1e12), spec.max.value_or(1e12));
      box->setValue(std::strtod(shown.c_str(), nullptr));
      box->setKeyboardTracking(false);
      connect(box, &QDoubleSpinBox::editingFinished, this, [box, emitValue] {
        std::ostringstream text;
        text << std::setprecision(12) << box->value();
        emitValue(text.str());
      });
      widget = box;
      break;
    }
    case app::ParamType::Bool: {
      auto* box = new QCheckBox;
      box->setChecked(shown == "true" || shown == "1");
      connect(box, &QCheckBox::toggled, this,
              [emitValue](bool on) { emitValue(on ? "true" : "false"); });
      widget = box;
      break;
    }
    case app::ParamType::Enum: {
      auto* box = new QComboBox;
      for (const auto& choice : spec.choices) box->addItem(qtText(choice));
      box->setCurrentText(qtText(shown));
      connect(box, &QComboBox::activated, this,
              [box, emitValue] { emitValue(stdText(box->currentText())); });
      widget = box;
      break;
    }
    case app::ParamType::Vec3: {
      auto* row = new QWidget;
      auto* h = new QHBoxLayout(row);
      h->setContentsMargins(0, 0, 0, 0);
      std::istringstream in(shown);
      std::vector<QDoubleSpinBox*> boxes;
      for (int i = 0; i < 3; ++i) {
        double v = 0;
        in >> v;
        auto* box = new QDoubleSpinBox;
        box->setDecimals(4);
        box->setRange(spec.min.value_or(-1e9), spec.max.value_or(1e9));
        box->setValue(v);
        box->setKeyboardTracking(false);
        box->setObjectName(QString("component%1").arg(i));
        h->addWidget(box);
        boxes.push_back(box);
      }
      for (auto* box : boxes) {
        connect(box, &QDoubleSpinBox::editingFinished, this, [boxes, emitValue] {
          std::ostringstream text;
          text << std::setprecision(12) << boxes[0]->value() << ' ' << boxes[1]->value() << ' '
               << boxes[2]->value();
          emitValue(text.str());
        });
      }
      widget = row;
      break;
    }
    case app::ParamType::File: {
      auto* row = new QWidget;
      auto* h = new QHBoxLayout(row);
      h->setContentsMargins(0, 0, 0, 0);
      auto* edit = new QLineEdit(qtText(shown));
      edit->setObjectName("text");
      auto* browse = new QToolButton;
      browse->setText("\u2026");
      h->addWidget(edit);
      h->addWidget(browse);
      connect(edit, &QLineEdit::editingFinished, this,
              [edit, emitValue] { emitValue(stdText(edit->text())); });
      connect(browse, &QToolButton::clicked, this, [this, edit, emitValue] {
        const QString file =
            QFileDialog::getSaveFileName(this, "Choose a file", edit->text(), QString(), nullptr,
                                         QFileDialog::DontConfirmOverwrite);
        if (!file.isEmpty()) {
          edit->setText(file);
          emitValue(stdText(file));
        }
      });
      widget = row;
      break;
    }
    case app::ParamType::String: {
      auto* edit = new QLineEdit(qtText(shown));
      connect(edit, &QLineEdit::editingFinished, this,
              [edit, emitValue] { emitValue(stdText(edit->text())); });
      widget = edit;
      break;
    }
  }
  widget->setObjectName("param:" + qtText(name));
  // Spin boxes with wide ranges ask for much width: let them shrink to the panel.
  for (auto* box : widget->findChildren<QAbstractSpinBox*>())
    box->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
  if (auto* box = qobject_cast<QAbstractSpinBox*>(widget))
    box->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
  widget->setMinimumWidth(60);
  QString tip = qtText(spec.doc);
  tip += (tip.isEmpty() ? "" : "\n") + QString("type: ") + qtText(app::toString(spec.type));
  tip +=
      "\ndefault: " + (spec.defaultValue.empty() ? QString("(empty)") : qtText(spec.defaultValue));
  if (spec.min) tip += QString("\nmin: %1").arg(*spec.min);
  if (spec.max) tip += QString("\nmax: %1").arg(*spec.max);
  widget->setToolTip(tip);
  return widget;
}

void PropertiesPanel::show(const app::Application& app, const app::Catalog& catalog,
                           const std::string& node) {
  node_ = node;
  dropLater(body_);
  if (node.empty() || nodeKind(app, node) == NodeKind::None) {
    clear();
    return;
  }
  body_ = new QWidget;
  auto* outer = new QVBoxLayout(body_);
  outer->setContentsMargins(0, 0, 0, 0);
  auto* scroll = new QScrollArea;
  scroll->setWidgetResizable(true);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  auto* content = new QWidget;
  auto* form = new QFormLayout(content);
  form->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
  scroll->setWidget(content);
  outer->addWidget(scroll);
  layout_->addWidget(body_);

  const app::Module* module = app::findModule(app, node);
  const app::Filter* filter = app::findFilter(app, node);
  const app::Instance* instance = app::findInstance(app, node);
  const std::vector<app::Param>* params = nullptr;
  const std::vector<app::ParamSpec>* specs = nullptr;
  std::string host;
  QString typeText, doc;
  if (module != nullptr) {
    params = &module->params;
    host = module->host;
    typeText = "module " + qtText(module->package + "/" + module->type);
    if (const auto* type = catalog.findModule(module->package, module->type)) {
      specs = &type->params;
      doc = qtText(type->doc);
    } else {
      doc = "Unknown module type: no installed package declares it.";
    }
  } else if (filter != nullptr) {
    params = &filter->params;
    host = filter->host;
    typeText = "filter " + qtText(filter->type);
    if (const auto* type = catalog.findFilter(filter->type)) {
      specs = &type->params;
      doc = qtText(type->doc);
    } else {
      doc = "Unknown filter type.";
    }
  } else {
    params = &instance->params;
    host = instance->host;
    typeText = "composite " + qtText(instance->composite);
  }

  auto* id = new QLineEdit(qtText(node));
  id->setObjectName("id");
  connect(id, &QLineEdit::editingFinished, this, [this, id, node] {
    if (stdText(id->text()) != node) Q_EMIT renameRequested(node, stdText(id->text()));
  });
  form->addRow("Id", id);
  auto* type = new QLabel("<b>" + typeText.toHtmlEscaped() + "</b>");
  form->addRow("Type", type);
  if (!doc.isEmpty()) {
    auto* docLabel = new QLabel(doc);
    docLabel->setWordWrap(true);
    docLabel->setStyleSheet("color: #555;");
    form->addRow(docLabel);
  }
  auto* hosts = new QComboBox;
  hosts->setObjectName("host");
  for (const auto& h : app.hosts) hosts->addItem(qtText(h.id));
  hosts->setCurrentText(qtText(app::effectiveHost(app, host)));
  connect(hosts, &QComboBox::activated, this,
          [this, hosts, node] { Q_EMIT hostChosen(node, stdText(hosts->currentText())); });
  form->addRow("Host", hosts);

  auto* heading = new QLabel("<b>Parameters</b>");
  form->addRow(heading);
  std::set<std::string> shownNames;
  if (specs != nullptr) {
    for (const auto& spec : *specs) {
      const app::Param* p = app::findParam(*params, spec.name);
      QWidget* editor = editorFor(spec, p == nullptr ? std::string() : p->value, p != nullptr);
      auto* row = new QWidget;
      auto* h = new QHBoxLayout(row);
      h->setContentsMargins(0, 0, 0, 0);
      h->addWidget(editor, 1);
      auto* reset = new QToolButton;
      reset->setText("\u21ba");
      reset->setToolTip("Reset to the default (" + qtText(spec.defaultValue) + ")");
      reset->setEnabled(p != nullptr);
      const std::string name = spec.name;
      connect(reset, &QToolButton::clicked, this,
              [this, node, name] { Q_EMIT parameterEdited(node, name, ""); });
      h->addWidget(reset);
      auto* label = new QLabel(qtText(spec.name) + (p == nullptr ? "" : " \u2022"));
      label->setToolTip(editor->toolTip());
      if (p == nullptr) label->setStyleSheet("color: #777;");
      form->addRow(label, row);
      shownNames.insert(spec.name);
    }
  }
  // Parameters the type does not declare (or of an instance): plain text.
  for (const auto& p : *params) {
    if (shownNames.count(p.name) != 0) continue;
    app::ParamSpec spec;
    spec.name = p.name;
    spec.doc = specs == nullptr ? "" : "Not declared by the type: validation reports it.";
    QWidget* editor = editorFor(spec, p.value, true);
    form->addRow(qtText(p.name), editor);
  }
  if (module != nullptr) {
    const auto* mtype = catalog.findModule(module->package, module->type);
    if (mtype != nullptr) {
      form->addRow(new QLabel("<b>Inputs: initial messages</b>"));
      for (const auto& port : mtype->ports) {
        if (!port.isInput) continue;
        auto* box = new QSpinBox;
        box->setObjectName("initial:" + qtText(port.name));
        box->setRange(0, 1000);
        box->setValue(app::inputConfigOrDefault(*module, port.name).initialMessages);
        box->setKeyboardTracking(false);
        box->setToolTip(
            "Messages the input holds before the first iteration (what breaks a cycle)");
        const std::string portName = port.name;
        connect(box, &QSpinBox::editingFinished, this, [this, box, node, portName] {
          Q_EMIT initialMessagesEdited(node, portName, box->value());
        });
        form->addRow(qtText(port.name), box);
      }
    }
  }
}

}  // namespace vrflow::editor::gui
