//! Wavefront MTL material libraries, mapped onto the Phong material: Ka → k_a, Kd → k_d
//! (`map_Kd` → an image texture), Ks → k_s, Ns → n, Ni → η, d (or 1 − Tr) → k_t = 1 − d,
//! and `illum`: 3 (and 5) make Ks the mirror k_r as well, 5 and 7 use Fresnel weights,
//! 4, 6, 7 and 9 are transparent glass.

use crate::diagnostics::SceneError;
use plenum_core::color::Color;
use plenum_core::material::PhongMaterial;
use plenum_core::texture::{ImageTexture, Texture};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Parses an MTL file; texture paths are relative to `base_dir`. Unknown statements are
/// returned as warnings.
pub fn parse_mtl(
    path: &Path,
    text: &str,
    base_dir: &Path,
) -> Result<(HashMap<String, PhongMaterial>, Vec<String>), SceneError> {
    let mut out = HashMap::new();
    let mut warnings = Vec::new();
    let mut current: Option<(String, PhongMaterial, f64)> = None;
    let finish = |c: Option<(String, PhongMaterial, f64)>,
                  out: &mut HashMap<String, PhongMaterial>| {
        if let Some((name, mut m, illum)) = c {
            let illum = illum as i32;
            if matches!(illum, 3 | 5 | 7) {
                m.reflective = m.specular.clone();
            }
            if matches!(illum, 5 | 7) {
                m.fresnel = true;
            }
            if matches!(illum, 4 | 6 | 7 | 9) && m.transmissive.is_black() {
                m.transmissive = Texture::Constant(Color::WHITE);
            }
            out.insert(name, m);
        }
    };
    let mut offset = 0;
    for (line_no, line) in text.split_inclusive('\n').enumerate() {
        let start = offset;
        offset += line.len();
        let content = line.split('#').next().unwrap_or("").trim();
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let rest: Vec<&str> = words.collect();
        let at =
            |msg: String| SceneError::at(path, text, start..start + line.trim_end().len(), msg);
        let numbers = |n: usize| -> Result<Vec<f64>, SceneError> {
            let v: Option<Vec<f64>> = rest
                .iter()
                .take(n)
                .map(|w| w.parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect();
            match v {
                Some(v) if v.len() == n => Ok(v),
                _ => Err(at(format!(
                    "expected {n} finite number(s) after `{keyword}`"
                ))),
            }
        };
        if keyword == "newmtl" {
            finish(current.take(), &mut out);
            let name = rest
                .first()
                .ok_or_else(|| at("expected a material name after `newmtl`".into()))?;
            let m = PhongMaterial {
                specular: Texture::Constant(Color::BLACK),
                ..PhongMaterial::default()
            };
            current = Some((name.to_string(), m, 2.0));
            continue;
        }
        let Some((_, m, illum)) = current.as_mut() else {
            warnings.push(format!(
                "warning: {}:{}: `{keyword}` before any `newmtl` is ignored",
                path.display(),
                line_no + 1
            ));
            continue;
        };
        let color = |v: Vec<f64>| Texture::Constant(Color::new(v[0], v[1], v[2]));
        match keyword {
            "Ka" => m.ambient = color(numbers(3)?),
            "Kd" => m.diffuse = color(numbers(3)?),
            "Ks" => m.specular = color(numbers(3)?),
            "Ke" => m.emissive = color(numbers(3)?),
            "Ns" => m.shininess = numbers(1)?[0].max(0.0),
            "Ni" => m.ior = numbers(1)?[0].max(1e-3),
            "d" => {
                m.transmissive =
                    Texture::Constant(Color::gray((1.0 - numbers(1)?[0]).clamp(0.0, 1.0)))
            }
            "Tr" => m.transmissive = Texture::Constant(Color::gray(numbers(1)?[0].clamp(0.0, 1.0))),
            "illum" => *illum = numbers(1)?[0],
            "map_Kd" => {
                let file = rest
                    .last()
                    .ok_or_else(|| at("expected a file after `map_Kd`".into()))?;
                match plenum_image::read_texture(&base_dir.join(file)) {
                    Ok(t) => {
                        let rgb = t
                            .rgb
                            .iter()
                            .map(|p| Color::new(p[0] as f64, p[1] as f64, p[2] as f64))
                            .collect();
                        if let Some(img) = ImageTexture::new(t.width, t.height, rgb, [1.0, 1.0]) {
                            m.diffuse = Texture::Image(Arc::new(img));
                        }
                    }
                    Err(e) => warnings.push(format!(
                        "warning: {}:{}: {e}; the diffuse colour is kept",
                        path.display(),
                        line_no + 1
                    )),
                }
            }
            _ => warnings.push(format!(
                "warning: {}:{}: `{keyword}` is not used",
                path.display(),
                line_no + 1
            )),
        }
    }
    finish(current.take(), &mut out);
    Ok((out, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phong_fields_and_illum_models() {
        let text = "newmtl red\nKa 0.1 0 0\nKd 0.8 0 0\nKs 0.5 0.5 0.5\nNs 50\nillum 3\nnewmtl glass\nNi 1.5\nd 0.1\nillum 7\nfoo 1\n";
        let (m, warnings) = parse_mtl(Path::new("t.mtl"), text, Path::new(".")).unwrap();
        let red = &m["red"];
        assert!(matches!(red.reflective, Texture::Constant(c) if c == Color::gray(0.5)));
        assert_eq!(red.shininess, 50.0);
        let glass = &m["glass"];
        assert!(glass.fresnel && glass.ior == 1.5);
        assert!(matches!(glass.transmissive, Texture::Constant(c) if (c.r - 0.9).abs() < 1e-12));
        assert_eq!(warnings.len(), 1);
        let e = parse_mtl(Path::new("t.mtl"), "newmtl a\nKd 1 x 0\n", Path::new(".")).unwrap_err();
        assert_eq!(e.line, 2);
    }
}
