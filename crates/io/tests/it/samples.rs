//! Small hand-written files exercising the odd corners of each format.

use std::fs;

use whet_io::{read, read_path, read_path_with_report, read_with_report, Format};
use whet_mesh::{DVec3, Mesh};

use crate::common::temp_path;

fn read_text(text: &str, format: Format) -> Mesh {
    read(text.as_bytes(), format).unwrap_or_else(|e| panic!("{format}: {e}"))
}

/// The unit square split into two triangles, as every sample below describes it.
fn square() -> Mesh {
    Mesh::new(
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

#[test]
fn off_with_comments_colours_and_quads() {
    let text = "# exported by hand\n\
                COFF\n\
                # counts follow\n\
                4 1 4\n\
                0 0 0 255 0 0 255\n\
                \n\
                1 0 0 0 255 0 255 # second\n\
                # a comment between vertices\n\
                1 1 0 0 0 255 255\n\
                0 1 0 9 9 9 9\n\
                4 0 1 2 3 0.1 0.2 0.3 1.0\n";
    assert_eq!(read_text(text, Format::Off), square());
    let same_line = "OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    assert_eq!(read_text(same_line, Format::Off), square());
    let crlf = "NOFF\r\n4 2 0\r\n0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n1 1 0 0 0 1\r\n0 1 0 0 0 1\r\n\
                3 0 1 2\r\n3 0 2 3\r\n";
    assert_eq!(read_text(crlf, Format::Off), square());
}

#[test]
fn obj_with_negative_indices_quads_and_attributes() {
    let text = "# a square\nmtllib square.mtl\no square\n\
                v 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.2 0.4 0.6\nv 0 1 0\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
                g top\nusemtl paper\ns 1\n\
                f -4/1/1 -3/2/1 -2/3/1 -1/4/1\n\
                l 1 3\n";
    assert_eq!(read_text(text, Format::Obj), square());
    let variants = [
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1//1 2//1 3//1 4//1\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 \\\n 3 4\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf -4 -2 -1\n",
        "f 1 2 3 4\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n",
    ];
    for text in variants {
        assert_eq!(read_text(text, Format::Obj), square(), "{text}");
    }
}

#[test]
fn ply_ascii_with_odd_property_order_extra_elements_and_lists() {
    let text = "ply\n\
                format ascii 1.0\n\
                comment properties out of order, an element before and one after\n\
                obj_info generator: hand\n\
                element camera 1\n\
                property float view_px\n\
                property list uchar float params\n\
                element vertex 4\n\
                property uchar red\n\
                property float32 y\n\
                property list uint8 int32 neighbours\n\
                property double z\n\
                property int16 x\n\
                element face 1\n\
                property uchar flags\n\
                property list uint8 uint32 vertex_indices\n\
                property list uchar float texcoord\n\
                element edge 2\n\
                property int vertex1\n\
                property int vertex2\n\
                end_header\n\
                0.5 3 1 2 3\n\
                255 0 2 1 3 0 0\n\
                255 0 0 0 1\n\
                255 1 1 2 0 1\n\
                255\n1\n0\n0\n0\n\
                7 4 0 1 2 3 8 0 0 1 0 1 1 0 1\n\
                0 1\n2 3\n";
    assert_eq!(read_text(text, Format::Ply), square());
}

#[test]
fn ply_binary_big_endian_with_list_in_vertex_and_trailing_element() {
    let header = "ply\nformat binary_big_endian 1.0\n\
                  element vertex 4\nproperty double x\nproperty list uchar float normal\n\
                  property double y\nproperty double z\n\
                  element face 2\nproperty list int int vertex_indices\n\
                  element edge 1\nproperty list ushort uchar pair\nend_header\n";
    let mut file = header.as_bytes().to_vec();
    for p in square().positions {
        file.extend_from_slice(&p.x.to_be_bytes());
        file.push(3);
        for c in [0.0f32, 0.0, 1.0] {
            file.extend_from_slice(&c.to_be_bytes());
        }
        file.extend_from_slice(&p.y.to_be_bytes());
        file.extend_from_slice(&p.z.to_be_bytes());
    }
    for t in square().triangles {
        file.extend_from_slice(&3i32.to_be_bytes());
        for i in t {
            file.extend_from_slice(&(i as i32).to_be_bytes());
        }
    }
    file.extend_from_slice(&2u16.to_be_bytes());
    file.extend_from_slice(&[0, 1]);
    assert_eq!(read(&file[..], Format::Ply).unwrap(), square());
    // Without the last byte the trailing element is incomplete.
    let e = read(&file[..file.len() - 1], Format::Ply).unwrap_err();
    assert!(e.to_string().contains("'edge' elements"), "{e}");
}

#[test]
fn ply_binary_little_endian_float_with_normals_and_quads() {
    let header = "ply\nformat binary_little_endian 1.0\n\
                  element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                  property float nx\nproperty float ny\nproperty float nz\n\
                  element face 1\nproperty list uchar int vertex_index\nend_header\n";
    let mut file = header.as_bytes().to_vec();
    for p in square().positions {
        for c in [p.x, p.y, p.z, 0.0, 0.0, 1.0] {
            file.extend_from_slice(&(c as f32).to_le_bytes());
        }
    }
    file.push(4);
    for i in [0i32, 1, 2, 3] {
        file.extend_from_slice(&i.to_le_bytes());
    }
    assert_eq!(read(&file[..], Format::Ply).unwrap(), square());
}

/// Binary STL of the square, with the given 80-byte header start.
fn square_stl(header_start: &[u8]) -> Vec<u8> {
    let mut file = vec![0u8; 80];
    file[..header_start.len()].copy_from_slice(header_start);
    file.extend_from_slice(&2u32.to_le_bytes());
    let m = square();
    for t in &m.triangles {
        file.extend_from_slice(&[0; 12]);
        for &i in t {
            for c in m.positions[i as usize].to_array() {
                file.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        file.extend_from_slice(&[0, 0]);
    }
    file
}

#[test]
fn stl_binary_whose_header_starts_with_solid() {
    let file = square_stl(b"solid square exported by a CAD tool");
    assert_eq!(read(&file[..], Format::Stl).unwrap(), square());
    let path = temp_path("solid-header.stl");
    fs::write(&path, &file).unwrap();
    let back = read_path(&path, None);
    fs::remove_file(&path).unwrap();
    assert_eq!(back.unwrap(), square());
    // Leading spaces and upper case make no difference.
    let file = square_stl(b"  SOLID");
    assert_eq!(read(&file[..], Format::Stl).unwrap(), square());
}

#[test]
fn stl_ascii_welds_corners() {
    let text = "solid square\n\
                  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n\
                  vertex 1 1 0\n    endloop\n  endfacet\n\
                  facet normal 0 0 1\n    outer loop\n      vertex 0.0 0.0 -0.0\n\
                  vertex 1 1 0\n      vertex 0 1 0\n    endloop\n  endfacet\n\
                endsolid square\n";
    assert_eq!(read_text(text, Format::Stl), square());
    let path = temp_path("ascii.stl");
    fs::write(&path, text).unwrap();
    let back = read_path(&path, None);
    fs::remove_file(&path).unwrap();
    assert_eq!(back.unwrap(), square());
}

#[test]
fn reports_name_what_was_skipped_and_plain_reads_agree() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
               f 1/1/1 2/2/1 3/3/1 4/4/1\n";
    let path = temp_path("report.obj");
    fs::write(&path, obj).unwrap();
    let with_report = read_path_with_report(&path, None);
    let plain = read_path(&path, None);
    fs::remove_file(&path).unwrap();
    let (mesh, report) = with_report.unwrap();
    assert_eq!(mesh, square());
    assert_eq!(plain.unwrap(), square());
    let pairs: Vec<(&str, u64)> = report
        .skipped
        .iter()
        .map(|s| (s.what.as_str(), s.count))
        .collect();
    assert_eq!(
        pairs,
        vec![("texture coordinates", 4), ("vertex normals", 1)]
    );
    assert_eq!(
        report.to_string(),
        "4 texture coordinates and 1 vertex normal"
    );
    let off = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    let (mesh, report) = read_with_report(off.as_bytes(), Format::Off).unwrap();
    assert_eq!(mesh, square());
    assert!(report.is_empty());
    assert_eq!(report.to_string(), "nothing");
}
