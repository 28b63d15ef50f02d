//! A minimal Collada (DAE) reader over `roxmltree`: the positions that a
//! file's triangles use, placed as its visual scene places them, in metres.
//!
//! Read: `<asset><unit meter>`; each `<geometry><mesh>`'s `<source>`
//! `<float_array>` (through its `<accessor stride offset>`), `<vertices>`
//! `POSITION` input, and the `VERTEX` index of every `<p>` of its
//! `<triangles>`, `<polylist>`, `<polygons>`, `<trifans>` and
//! `<tristrips>`; the scene's `<node>` tree (`<matrix>`, `<translate>`,
//! `<rotate>`, `<scale>`, `<instance_geometry>`, `<instance_node>`). Without a
//! visual scene every geometry is taken as it is. `<up_axis>` is not applied,
//! as the ROS tools do not apply it (they reset assimp's up-axis rotation).
//! Anything else (materials, normals, texture coordinates, lines) is
//! ignored; `<lookat>` and `<skew>` are refused.
//!
//! Why not the `dae-parser` crate (0.11): it stores every number as `f32`,
//! its vertex importer panics on inputs it does not know, and a convex hull
//! needs none of the rest of its document model.

use std::collections::HashMap;

use nalgebra::{Matrix4, Point3, Rotation3, Unit};
use roxmltree::{Document, Node, ParsingOptions};

use super::formats::Points;
use crate::math::Vec3;

/// Deepest node nesting followed (an `<instance_node>` cycle ends here).
const MAX_DEPTH: usize = 64;

type Res<T> = Result<T, String>;

/// The used positions of a DAE file, in metres (module docs).
pub(crate) fn points(bytes: &[u8]) -> Res<Points> {
    let text = std::str::from_utf8(bytes).map_err(|_| "the file is not UTF-8 text")?;
    let options = ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let doc = Document::parse_with_options(text, options).map_err(|e| e.to_string())?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        return Err("the root element is not <COLLADA>".into());
    }
    let meshes = Geometries::read(root)?;
    let unit = Matrix4::new_scaling(unit_metres(root)?);
    let mut out = Vec::new();
    match visual_scene(root) {
        Some(scene) => {
            let placer = Placer {
                meshes: &meshes,
                nodes: nodes_by_id(root),
            };
            for node in children(scene, "node") {
                placer.place(node, &unit, 0, &mut out)?;
            }
        }
        None => {
            for points in meshes.0.values() {
                out.extend(points.iter().map(|p| transform(&unit, p)));
            }
        }
    }
    Ok(out)
}

fn children<'a, 'i>(node: Node<'a, 'i>, name: &'static str) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

fn child<'a, 'i>(node: Node<'a, 'i>, name: &'static str) -> Option<Node<'a, 'i>> {
    children(node, name).next()
}

/// The id an `url="#id"` or `source="#id"` attribute points at.
fn target<'a>(node: Node<'a, '_>, attribute: &str) -> Res<&'a str> {
    let url = node
        .attribute(attribute)
        .ok_or_else(|| format!("<{}> has no {attribute}", node.tag_name().name()))?;
    url.strip_prefix('#')
        .ok_or_else(|| format!("{attribute}=\"{url}\": only references inside the file are read"))
}

fn numbers<T: std::str::FromStr>(node: Node<'_, '_>) -> Res<Vec<T>> {
    let text = node.text().unwrap_or("");
    text.split_ascii_whitespace()
        .map(|w| w.parse().map_err(|_| format!("'{w}' is not a number")))
        .collect()
}

fn unit_metres(root: Node<'_, '_>) -> Res<f64> {
    let unit = child(root, "asset")
        .and_then(|a| child(a, "unit"))
        .and_then(|u| u.attribute("meter"));
    match unit.map(str::parse::<f64>) {
        None => Ok(1.0),
        Some(Ok(m)) if m.is_finite() && m > 0.0 => Ok(m),
        Some(_) => Err("<unit meter> must be a positive number".into()),
    }
}

/// The used positions of each `<geometry>` with a `<mesh>`, by id.
struct Geometries<'a>(HashMap<&'a str, Points>);

impl<'a> Geometries<'a> {
    fn read(root: Node<'a, '_>) -> Res<Self> {
        let mut out = HashMap::new();
        for library in children(root, "library_geometries") {
            for geometry in children(library, "geometry") {
                if let (Some(id), Some(mesh)) = (geometry.attribute("id"), child(geometry, "mesh"))
                {
                    out.insert(id, mesh_points(mesh)?);
                }
            }
        }
        Ok(Self(out))
    }
}

/// The positions of one `<mesh>` that its primitives' `<p>` lists use.
fn mesh_points(mesh: Node<'_, '_>) -> Res<Points> {
    let mut sources = HashMap::new();
    for source in children(mesh, "source") {
        if let Some(id) = source.attribute("id") {
            sources.insert(id, source);
        }
    }
    let mut vertices = HashMap::new();
    for v in children(mesh, "vertices") {
        let position = children(v, "input").find(|i| i.attribute("semantic") == Some("POSITION"));
        if let (Some(id), Some(input)) = (v.attribute("id"), position) {
            let source = sources
                .get(target(input, "source")?)
                .ok_or("a POSITION input names a missing <source>")?;
            vertices.insert(id, positions(*source)?);
        }
    }
    let mut out = Vec::new();
    for primitive in mesh.children().filter(|c| is_polygonal(c)) {
        let Some((offset, stride, id)) = vertex_input(primitive)? else {
            continue;
        };
        let table = vertices
            .get(id)
            .ok_or("a VERTEX input names missing <vertices>")?;
        for p in children(primitive, "p") {
            for index in numbers::<usize>(p)?
                .into_iter()
                .skip(offset)
                .step_by(stride)
            {
                out.push(
                    *table
                        .get(index)
                        .ok_or("a <p> index names a missing vertex")?,
                );
            }
        }
    }
    Ok(out)
}

fn is_polygonal(node: &Node<'_, '_>) -> bool {
    let polygonal = ["triangles", "polylist", "polygons", "trifans", "tristrips"];
    node.is_element() && polygonal.contains(&node.tag_name().name())
}

/// The `VERTEX` input of a primitive: its offset, the number of indices per
/// vertex (largest input offset + 1) and the `<vertices>` id.
fn vertex_input<'a>(primitive: Node<'a, '_>) -> Res<Option<(usize, usize, &'a str)>> {
    let mut stride = 0;
    let mut vertex = None;
    for input in children(primitive, "input") {
        let offset: usize = input
            .attribute("offset")
            .unwrap_or("0")
            .parse()
            .map_err(|_| "an <input offset> is not a whole number")?;
        stride = stride.max(offset + 1);
        if input.attribute("semantic") == Some("VERTEX") {
            vertex = Some((offset, target(input, "source")?));
        }
    }
    Ok(vertex.map(|(offset, id)| (offset, stride, id)))
}

/// The points of a `<source>`: the first three values of each accessor
/// element.
fn positions(source: Node<'_, '_>) -> Res<Points> {
    let values: Vec<f64> =
        numbers(child(source, "float_array").ok_or("a <source> has no <float_array>")?)?;
    let accessor = child(source, "technique_common").and_then(|t| child(t, "accessor"));
    let attribute = |name: &str, default: usize| -> Res<usize> {
        match accessor.and_then(|a| a.attribute(name)) {
            None => Ok(default),
            Some(v) => v
                .parse()
                .map_err(|_| format!("<accessor {name}> is not a whole number")),
        }
    };
    let (stride, offset) = (attribute("stride", 3)?, attribute("offset", 0)?);
    let count = attribute("count", values.len().saturating_sub(offset) / stride.max(1))?;
    if stride < 3 {
        return Err("a position <accessor> needs a stride of at least 3".into());
    }
    (0..count)
        .map(|k| {
            let at = offset + k * stride;
            let xyz = values
                .get(at..at + 3)
                .ok_or("an <accessor> reads past its <float_array>")?;
            Ok(Vec3::new(xyz[0], xyz[1], xyz[2]))
        })
        .collect()
}

fn visual_scene<'a, 'i>(root: Node<'a, 'i>) -> Option<Node<'a, 'i>> {
    let wanted = child(root, "scene")
        .and_then(|s| child(s, "instance_visual_scene"))
        .and_then(|i| target(i, "url").ok());
    let mut scenes =
        children(root, "library_visual_scenes").flat_map(|l| children(l, "visual_scene"));
    match wanted {
        Some(id) => scenes.find(|s| s.attribute("id") == Some(id)),
        None => scenes.next(),
    }
}

fn nodes_by_id<'a, 'i>(root: Node<'a, 'i>) -> HashMap<&'a str, Node<'a, 'i>> {
    root.descendants()
        .filter(|n| n.is_element() && n.tag_name().name() == "node")
        .filter_map(|n| Some((n.attribute("id")?, n)))
        .collect()
}

fn transform(m: &Matrix4<f64>, p: &Vec3) -> Vec3 {
    m.transform_point(&Point3::from(*p)).coords
}

/// Walks the scene's node tree, placing each instanced geometry.
struct Placer<'m, 'a, 'i> {
    meshes: &'m Geometries<'a>,
    nodes: HashMap<&'a str, Node<'a, 'i>>,
}

impl<'a, 'i> Placer<'_, 'a, 'i> {
    fn place(
        &self,
        node: Node<'a, 'i>,
        parent: &Matrix4<f64>,
        depth: usize,
        out: &mut Points,
    ) -> Res<()> {
        if depth > MAX_DEPTH {
            return Err(format!(
                "<node> nesting deeper than {MAX_DEPTH} (an <instance_node> cycle?)"
            ));
        }
        let mut m = *parent;
        for element in node.children().filter(|c| c.is_element()) {
            match element.tag_name().name() {
                "matrix" | "translate" | "rotate" | "scale" => m *= local_transform(element)?,
                "lookat" | "skew" => {
                    return Err(format!("<{}> is not supported", element.tag_name().name()));
                }
                "instance_geometry" => {
                    let id = target(element, "url")?;
                    let points = self
                        .meshes
                        .0
                        .get(id)
                        .ok_or_else(|| format!("no <geometry id=\"{id}\"> with a <mesh>"))?;
                    out.extend(points.iter().map(|p| transform(&m, p)));
                }
                "node" => self.place(element, &m, depth + 1, out)?,
                "instance_node" => {
                    let id = target(element, "url")?;
                    let inner = self
                        .nodes
                        .get(id)
                        .ok_or_else(|| format!("no <node id=\"{id}\">"))?;
                    self.place(*inner, &m, depth + 1, out)?;
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// The matrix of one transform element (COLLADA: row-major matrices,
/// rotation angles in degrees).
fn local_transform(element: Node<'_, '_>) -> Res<Matrix4<f64>> {
    let name = element.tag_name().name();
    let v: Vec<f64> = numbers(element)?;
    let wanted = match name {
        "matrix" => 16,
        "rotate" => 4,
        _ => 3,
    };
    if v.len() != wanted || !v.iter().all(|x| x.is_finite()) {
        return Err(format!("<{name}> needs {wanted} finite numbers"));
    }
    Ok(match name {
        "matrix" => Matrix4::from_row_slice(&v),
        "translate" => Matrix4::new_translation(&Vec3::new(v[0], v[1], v[2])),
        "scale" => Matrix4::new_nonuniform_scaling(&Vec3::new(v[0], v[1], v[2])),
        _ => {
            let axis = Unit::try_new(Vec3::new(v[0], v[1], v[2]), 1e-12)
                .ok_or("<rotate> has a zero axis")?;
            Rotation3::from_axis_angle(&axis, v[3].to_radians()).to_homogeneous()
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One triangle, as a `<polylist>`, instanced through `<instance_node>`
    /// under a node that scales, turns and moves it (in millimetres).
    const PLACED: &str = r##"<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema">
  <asset><unit meter="0.001"/></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="12">9 9 9 1 0 0 0 1 0 0 0 1</float_array>
      <technique_common><accessor source="#pa" count="4" stride="3"/></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <polylist count="1"><input semantic="VERTEX" source="#v" offset="0"/><vcount>3</vcount><p>1 2 3</p></polylist>
  </mesh></geometry></library_geometries>
  <library_nodes><node id="part"><instance_geometry url="#g"/></node></library_nodes>
  <library_visual_scenes><visual_scene id="s"><node>
    <matrix>1 0 0 100 0 1 0 0 0 0 1 0 0 0 0 1</matrix>
    <rotate>0 0 1 90</rotate>
    <scale>2 2 2</scale>
    <instance_node url="#part"/>
  </node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##;

    #[test]
    fn scene_transforms_and_units_place_the_used_vertices() {
        let points = points(PLACED.as_bytes()).unwrap();
        // x' = 0.1 + 0.002 (-y), y' = 0.002 x, z' = 0.002 z; the unused
        // first position is left out.
        let expected = [
            Vec3::new(0.1, 0.002, 0.0),
            Vec3::new(0.098, 0.0, 0.0),
            Vec3::new(0.1, 0.0, 0.002),
        ];
        assert_eq!(points.len(), 3);
        for (p, e) in points.iter().zip(&expected) {
            assert!((p - e).norm() < 1e-12, "{p:?} vs {e:?}");
        }
    }

    #[test]
    fn broken_references_are_errors() {
        let missing = PLACED.replace(r##"url="#part""##, r##"url="#nothing""##);
        assert!(points(missing.as_bytes()).unwrap_err().contains("nothing"));
        let cycle = PLACED.replace(
            r##"<instance_geometry url="#g"/></node>"##,
            r##"<instance_node url="#part"/></node>"##,
        );
        assert!(points(cycle.as_bytes()).unwrap_err().contains("deeper"));
        let past = PLACED.replace("<p>1 2 3</p>", "<p>1 2 7</p>");
        assert!(
            points(past.as_bytes())
                .unwrap_err()
                .contains("missing vertex")
        );
    }
}
