//! Typed ids: what the names of a case file resolve to. Validation resolves every name once and
//! stores the ids in the [`super::Case`] it makes; the modules past it look tables up by id, a
//! lookup that cannot fail.

use super::schema::{
    BearingCapacity, CookMembrane, DamBreak, ElasticColumn, HarmonicColumn, HollowCylinder, Lame,
    LargeStrainConsolidation, Patch, Runout, ShockWave, StiffnessMap, Terzaghi, VerticalCut,
};

macro_rules! id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(usize);

        impl $name {
            /// The id of the table at `index` of its array in the case file (made by validation,
            /// which knows the index exists).
            pub(crate) fn new(index: usize) -> Self {
                $name(index)
            }

            /// The table's index in its array of the case file.
            pub fn index(self) -> usize {
                self.0
            }
        }
    };
}

id!(
    /// A `[[materials]]` table.
    MaterialId
);
id!(
    /// A `[[bodies]]` table; also the `body` number of its material points.
    BodyId
);
id!(
    /// A `[[loads]]` table.
    LoadId
);
id!(
    /// A `[[boundaries]]` table.
    BoundaryId
);
id!(
    /// A `[[time_functions]]` table.
    TimeFunctionId
);
id!(
    /// A `[[stages]]` table.
    StageId
);

/// The names of a case resolved, table by table (each vector in the order of its array).
#[derive(Debug, Clone)]
pub(crate) struct Links {
    /// The material of each body.
    pub body_materials: Vec<MaterialId>,
    /// What each boundary names.
    pub boundaries: Vec<BoundaryLinks>,
    /// What each load names.
    pub loads: Vec<LoadLinks>,
    /// The verification with what it names.
    pub verification: Option<LinkedVerification>,
}

/// What a boundary names.
#[derive(Debug, Clone)]
pub(crate) struct BoundaryLinks {
    /// The body of its moving surface.
    pub surface_body: Option<BodyId>,
    /// Its time function.
    pub time_function: Option<TimeFunctionId>,
}

/// What a load names.
#[derive(Debug, Clone)]
pub(crate) struct LoadLinks {
    /// The bodies it is limited to (a particle traction's `body`, a body force's `bodies`).
    pub bodies: Option<Vec<BodyId>>,
    /// Its time function.
    pub time_function: Option<TimeFunctionId>,
}

/// The case's verification with the tables its names resolve to: each kind's parameters beside
/// its ids.
#[derive(Debug, Clone)]
pub enum LinkedVerification {
    /// `terzaghi`.
    Terzaghi(Terzaghi, BodyAndLoad),
    /// `harmonic_column`.
    HarmonicColumn(HarmonicColumn, BodyAndLoad),
    /// `elastic_column`.
    ElasticColumn(ElasticColumn, ElasticColumnIds),
    /// `bearing_capacity`.
    BearingCapacity(BearingCapacity, FootingIds),
    /// `large_strain_consolidation`.
    LargeStrainConsolidation(LargeStrainConsolidation, BodyAndLoad),
    /// `patch`.
    Patch(Patch, PatchIds),
    /// `lame`.
    Lame(Lame, BodyAndLoad),
    /// `hollow_cylinder`.
    HollowCylinder(HollowCylinder, BodyAndLoad),
    /// `stiffness_map`: its body.
    StiffnessMap(StiffnessMap, BodyId),
    /// `vertical_cut`: its body.
    VerticalCut(VerticalCut, BodyId),
    /// `cook_membrane`: its body.
    CookMembrane(CookMembrane, BodyId),
    /// `dam_break`.
    DamBreak(DamBreak, DamBreakIds),
    /// `runout`.
    Runout(Runout, RunoutIds),
    /// `shock_wave`.
    ShockWave(ShockWave, BodyAndLoad),
}

/// The body a check follows and the load it compares with.
#[derive(Debug, Clone, Copy)]
pub struct BodyAndLoad {
    /// `body`.
    pub body: BodyId,
    /// `load`.
    pub load: LoadId,
}

/// What an elastic column names.
#[derive(Debug, Clone, Copy)]
pub struct ElasticColumnIds {
    /// `body`.
    pub body: BodyId,
    /// `gravity`: a body force.
    pub gravity: LoadId,
    /// `surcharge`: a particle or nodal traction.
    pub surcharge: Option<LoadId>,
}

/// What a bearing-capacity check names.
#[derive(Debug, Clone, Copy)]
pub struct FootingIds {
    /// `soil`.
    pub soil: BodyId,
    /// What loads the footing.
    pub loading: Loading,
}

/// What loads a footing.
#[derive(Debug, Clone, Copy)]
pub enum Loading {
    /// `load`: a traction, or a body force on the footing body.
    Load(LoadId),
    /// `footing`: a boundary that moves the nodes under the footing (displacement control).
    Footing(BoundaryId),
}

/// What a patch test names.
#[derive(Debug, Clone, Copy)]
pub struct PatchIds {
    /// `body`.
    pub body: BodyId,
    /// `boundary`: it has a `velocity_gradient`.
    pub boundary: BoundaryId,
}

/// What a dam break names.
#[derive(Debug, Clone, Copy)]
pub struct DamBreakIds {
    /// `body`: a rectangle.
    pub body: BodyId,
    /// `gravity`: a body force.
    pub gravity: LoadId,
    /// `settle_stage`: not the last stage.
    pub settle_stage: StageId,
}

/// What a run-out check names.
#[derive(Debug, Clone, Copy)]
pub struct RunoutIds {
    /// `body`.
    pub body: BodyId,
    /// `trigger_stage`.
    pub trigger_stage: StageId,
}
