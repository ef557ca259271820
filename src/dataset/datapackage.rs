//! `dataset/datapackage.json`: a Frictionless Data Package (Tabular Data Package, Table
//! Schema) describing the compiled table, generated from the vocabulary so it cannot drift;
//! `survey validate` fails when the committed file differs from what it should be.

use serde_json::{Value as Json, json};

use super::Dataset;
use super::record::RobotClass;
use super::vocabulary::FieldType;

pub const FILE: &str = "datapackage.json";

/// The data package JSON text (sorted keys, two-space indent, trailing newline).
pub fn datapackage_json(ds: &Dataset) -> String {
    let mut fields = vec![
        json!({"name": "id", "type": "string", "description": "Record id (file robots/ID.toml).",
               "constraints": {"required": true, "unique": true, "pattern": "^[a-z0-9-]+$"}}),
        json!({"name": "name", "type": "string", "description": "Robot name.", "constraints": {"required": true}}),
        json!({"name": "class", "type": "string", "description": "Robot class (paper, Sec. II); hybrid: not purely legged.",
               "constraints": {"required": true, "enum": RobotClass::ALL.map(|c| c.as_str())}}),
        json!({"name": "fit", "type": "boolean", "description": "Used in the power-law fits.", "constraints": {"required": true}}),
        json!({"name": "exclusion", "type": "string", "description": "Why a kept robot is not fitted."}),
    ];
    for f in ds.vocab.compiled_fields() {
        let ty = match f.field_type {
            FieldType::Number => "number",
            FieldType::Integer => "integer",
            FieldType::Text => "string",
            FieldType::Bool => "boolean",
        };
        let mut field = json!({"name": f.name, "type": ty, "description": f.description});
        let mut constraints = serde_json::Map::new();
        if let Some(m) = f.min {
            constraints.insert("minimum".into(), json_number(m, f.field_type));
        }
        if let Some(m) = f.max {
            constraints.insert("maximum".into(), json_number(m, f.field_type));
        }
        if !f.allowed.is_empty() {
            constraints.insert("enum".into(), json!(f.allowed));
        }
        if !constraints.is_empty() {
            field["constraints"] = Json::Object(constraints);
        }
        if !f.unit.is_empty() && f.unit != "1" {
            field["unit"] = json!(f.unit);
        }
        fields.push(field);
    }
    fields.push(json!({"name": "sources", "type": "string", "description": "URLs (or lab titles) of the record's sources, separated by ' ; '."}));
    let pkg = json!({
        "profile": "tabular-data-package",
        "name": "robot-survey",
        "title": ds.meta.name,
        "description": ds.meta.description,
        "version": ds.meta.version,
        "licenses": [{"name": ds.meta.license}],
        "resources": [{
            "name": "robots",
            "path": format!("releases/{}/robots.csv", ds.meta.version),
            "profile": "tabular-data-resource",
            "format": "csv",
            "mediatype": "text/csv",
            "encoding": "utf-8",
            "schema": {"fields": fields, "primaryKey": "id", "missingValues": [""]}
        }]
    });
    let mut s = serde_json::to_string_pretty(&pkg).unwrap_or_default();
    s.push('\n');
    s
}

fn json_number(x: f64, ty: FieldType) -> Json {
    if ty == FieldType::Integer {
        json!(x as i64)
    } else {
        json!(x)
    }
}
