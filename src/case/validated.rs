//! The validated case: a case file whose ranges, combinations and names validation has checked,
//! with the names of its sections resolved to typed ids. Every module past validation takes a [`Case`]; it reads
//! the file's tables through `Deref` (`case.grid`, `case.stages`), and the tables a name points at
//! through the ids (`case.material_of(body)`).

use super::ids::{BodyId, BoundaryId, Links, LoadId, MaterialId, StageId, TimeFunctionId};
use super::schema::{Body, Boundary, CaseFile, Load, Material, Stage, TimeFunction};

/// A validated case (only `crate::validation` makes one).
#[derive(Debug, Clone)]
pub struct Case {
    file: CaseFile,
    links: Links,
}

impl std::ops::Deref for Case {
    type Target = CaseFile;

    fn deref(&self) -> &CaseFile {
        &self.file
    }
}

/// The table an id points at, one accessor per section (`case.body(id)`, `case.stage(id)`).
macro_rules! table_accessors {
    ($($(#[$doc:meta])* $name:ident($id:ty) -> $table:ident: $ty:ty;)*) => {
        impl Case {
            $($(#[$doc])* pub fn $name(&self, id: $id) -> &$ty {
                &self.file.$table[id.index()]
            })*
        }
    };
}

table_accessors! {
    /// A body.
    body(BodyId) -> bodies: Body;
    /// A material.
    material(MaterialId) -> materials: Material;
    /// A load.
    load(LoadId) -> loads: Load;
    /// A boundary.
    boundary(BoundaryId) -> boundaries: Boundary;
    /// A stage.
    stage(StageId) -> stages: Stage;
    /// A time function.
    time_function(TimeFunctionId) -> time_functions: TimeFunction;
}

impl Case {
    /// The case of `file` with its names resolved to `links`; validation's last step.
    pub(crate) fn new(file: CaseFile, links: Links) -> Case {
        Case { file, links }
    }

    /// The case file as written (with each stage's Δt filled in).
    pub fn file(&self) -> &CaseFile {
        &self.file
    }

    /// The bodies' ids, in the file's order.
    pub fn body_ids(&self) -> impl Iterator<Item = BodyId> + use<> {
        (0..self.file.bodies.len()).map(BodyId::new)
    }

    /// The loads' ids, in the file's order.
    pub fn load_ids(&self) -> impl Iterator<Item = LoadId> + use<> {
        (0..self.file.loads.len()).map(LoadId::new)
    }

    /// The boundaries' ids, in the file's order.
    pub fn boundary_ids(&self) -> impl Iterator<Item = BoundaryId> + use<> {
        (0..self.file.boundaries.len()).map(BoundaryId::new)
    }

    /// `body`'s initial fields, parsed (empty where it gives none).
    pub fn initial_values(&self, body: BodyId) -> &super::schema::InitialValues {
        &self.links.body_initial[body.index()]
    }

    /// The id of `body`'s material.
    pub fn material_id_of(&self, body: BodyId) -> MaterialId {
        self.links.body_materials[body.index()]
    }

    /// `body`'s material.
    pub fn material_of(&self, body: BodyId) -> &Material {
        self.material(self.material_id_of(body))
    }

    /// The body whose moving surface `boundary` fixes, if it is a surface.
    pub fn surface_body(&self, boundary: BoundaryId) -> Option<BodyId> {
        self.links.boundaries[boundary.index()].surface_body
    }

    /// The time function scaling `boundary`'s motion, if it names one.
    pub fn boundary_time_function(&self, boundary: BoundaryId) -> Option<&TimeFunction> {
        self.links.boundaries[boundary.index()].time_function.map(|f| self.time_function(f))
    }

    /// The time function scaling `load`, if it names one.
    pub fn load_time_function(&self, load: LoadId) -> Option<&TimeFunction> {
        self.links.loads[load.index()].time_function.map(|f| self.time_function(f))
    }

    /// The bodies `load` is limited to, if it is (a particle traction's `body`, a body force's
    /// `bodies`).
    pub fn load_bodies(&self, load: LoadId) -> Option<&[BodyId]> {
        self.links.loads[load.index()].bodies.as_deref()
    }

    /// The first body containing `p` (bodies earlier in the file take precedence), if any, in a case
    /// of dimension `D`.
    pub fn body_at<const D: usize>(&self, p: [f64; D]) -> Option<BodyId> {
        self.body_ids().find(|&b| self.body_holds(self.body(b), p))
    }

    /// Mass density of the material at `p` [kg/m³]: the saturated mixture (1 − n)ρ_s + nρ_w, or 0
    /// outside every body.
    pub fn density_at<const D: usize>(&self, p: [f64; D]) -> f64 {
        self.body_at(p).map_or(0.0, |b| {
            let m = self.material_of(b);
            (1.0 - m.porosity) * m.solid_density + m.porosity * m.water_density
        })
    }

    /// The top of the material above `p` (the highest point of the bodies on the vertical line
    /// through p, sampled at `dy`), and ∫_y^{top} ρ dy along it [kg/m²].
    pub fn column_above<const D: usize>(&self, p: [f64; D], dy: f64) -> (f64, f64) {
        let top = self.bodies.iter().map(|b| b.shape.bounds().1[1]).fold(p[1], f64::max);
        let n = ((top - p[1]) / dy).ceil().max(1.0) as usize;
        let h = (top - p[1]) / n as f64;
        let (mut mass, mut surface) = (0.0, p[1]);
        for i in 0..n {
            let mut q = p;
            q[1] = p[1] + (i as f64 + 0.5) * h;
            let rho = self.density_at(q);
            mass += rho * h;
            if rho > 0.0 {
                surface = p[1] + (i + 1) as f64 * h;
            }
        }
        (surface, mass)
    }
}
