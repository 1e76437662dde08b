!> The contact and friction mode of N bodies (docs/method.md section 9): which rows are held
!> closed, which bodies stick, which way sliding friction acts, and the accelerations within
!> the mode, for any N (the two-body engine's enumeration of two bodies' modes is gone).
!>
!> At an event point the bodies fall into clusters joined by candidate rows (closed, zero
!> normal velocity) between bodies; each cluster with a candidate row or a body at rest with
!> friction is one complementarity problem: a cluster whose rows form a path (a train, a
!> chain) by impact1d_path_mode in O(its size), any other by impact1d_cluster_mode (Lemke's
!> method: no enumeration of 3^N modes); a body alone and sliding needs none. Work is
!> O(N + rows) to partition plus the clusters' own solves.
!>
!> Within a mode every row is of the form (-1, 1), (1, -1) or a wall, so held rows make their
!> ends move as one: the bodies fall into groups (union-find over held rows and stuck bodies,
!> 0 the ground). A group joined to the ground or to a stuck body has a = 0; any other moves
!> with a = (sum of f_i + f_slide_i) / (sum of m_i), its contact forces internal. That is
!> O(N) per stage, whatever the clusters. A geared row (-n, 1) makes its ends move at v_b =
!> n v_a instead: in a geared scene each body has a scale s_i in its group (gear_groups) and
!> a_i = s_i (sum s_j f_j) / (sum m_j s_j^2) (docs/method.md section 14).
module impact1d_body_mode
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_clusters, only: uf_join, uf_find
  use impact1d_cluster_mode, only: cluster_work_type, cluster_reserve, cluster_mode, cluster_solved
  use impact1d_lcp, only: lcp_too_large
  use impact1d_path_mode, only: path_work_type, path_reserve, path_order, path_mode
  use impact1d_friction_laws, only: slip, sliding_bound, belt_moving, belt_rate
  implicit none
  private
  public :: body_mode_type, mode_work_type, new_mode, solve_body_mode, same_mode, mode_solved
  public :: mode_reserve, gathered_mode, solve_cluster
  public :: drive_accelerations, shift_to_drives, drive_components, relative_velocity

  integer, parameter :: mode_solved = cluster_solved   !< otherwise an impact1d_lcp status
  !> The largest cluster problem solved densely (rows + 2 bodies' unknowns): its matrices take
  !> about 24 n^2 bytes, 2.4 GB here. A cluster whose rows form a path (a train) is solved
  !> in O(n) by impact1d_path_mode, whatever its size.
  integer, parameter, public :: max_dense_unknowns = 10000

  type :: body_mode_type
    logical, allocatable :: active(:)        !< (nr) rows held closed
    logical, allocatable :: stuck(:)         !< (N) bodies held by static friction
    real(wp), allocatable :: sgn(:)          !< (N) sliding direction: friction is -c_i sgn_i
    real(wp), allocatable :: f_slide(:)      !< (N) the sliding friction forces -c_i sgn_i
    integer, allocatable :: group(:)         !< (N) the body's group (a union-find root); 0: held still
    real(wp), allocatable :: group_mass(:)   !< (0:N) mass of the group rooted at each index
    !> (N) geared scenes only (scene%geared; else unallocated): each body's velocity per unit
    !> of its group's, s_i (a held row of normal (-n, 1) makes v_b = n v_a); the group then
    !> moves as one coordinate q with x_i' = s_i q', its mass sum m_i s_i^2 (group_mass) and
    !> its force sum s_i f_i (docs/method.md section 14)
    real(wp), allocatable :: scale(:)
    !> (N) the drive of the moving ground whose held rows hold the body's group (group 0),
    !> else 0 (scenes with drives only: set_groups)
    integer, allocatable :: drive(:)
    !> (n_stops) the compliant stops engaged (docs/method.md section 10), switched at event
    !> points only (impact1d_nbody_event's switch_stops); allocated by the run (unallocated:
    !> a scene without stops)
    logical, allocatable :: engaged(:)
    !> Some row is held or some body stuck: conditions that forces can break.
    logical :: held = .false.
    !> (nf) friction contacts between bodies (&friction): the direction of the relative
    !> velocity v_b - v_a they slide in (the force -F sgn on b, +F sgn on a), 0 for none;
    !> stuck: at relative rest, held there by static friction (its ends in one group).
    !> Allocated by the first solve of a scene that has such contacts.
    real(wp), allocatable :: friction_sgn(:)
    logical, allocatable :: friction_stuck(:)
  contains
    procedure :: acceleration
    procedure :: rate_response
    procedure :: geared_response
  end type body_mode_type

  !> The mode solve's memory, sized by the run (new_mode) and grown at event points only when
  !> a cluster is larger than any before.
  type :: mode_work_type
    !> The dense solve's (allocated by its first cluster, dense_reserve: a run whose clusters are
    !> all paths or bodies alone, a short call's, does not copy its 2 kB in and out)
    type(cluster_work_type), allocatable :: cluster
    !> The path solve's (allocated by mode_reserve: a run with no cluster to solve, a short
    !> call's, does not copy its 2.9 kB in and out)
    type(path_work_type), allocatable :: path
    !> Solve every cluster densely, paths too (tests compare the two solves).
    logical :: dense_only = .false.
    integer, allocatable :: root(:)                  !< (0:N) union-find
    integer, allocatable :: first(:), member(:)      !< (N+1), (N) bodies of each cluster, by root
    integer, allocatable :: first_row(:), row(:)     !< (N+1), (nr) candidate rows of each cluster
    integer, allocatable :: local(:)                 !< (0:N) a body's index in its cluster, 0 the ground
    logical, allocatable :: needs_solve(:)           !< (N) by root: a candidate row or a body at rest
    ! One cluster's problem, gathered (size: the largest cluster so far).
    real(wp), allocatable, dimension(:) :: mass, force, rate, friction, static, velocity, acc, sgn, &
      contact_force, friction_force, acc_rate
    logical, allocatable :: candidate(:), active(:), stuck(:)
    integer, allocatable :: row_body(:, :)
    real(wp), allocatable :: row_normal(:, :)
    !> (N) the force of the friction contacts that slide on each body (scenes with &friction)
    real(wp), allocatable :: pair_force(:)
  end type mode_work_type

contains

  !> A mode of n bodies and n_rows rows with nothing held (each body alone, no friction),
  !> and the work of its solves. Both as declared (a run's new memory, nothing allocated):
  !> intent(out) would have gfortran build their default initialisation and copy it in.
  subroutine new_mode(n, n_rows, mode, work)
    integer, intent(in) :: n, n_rows
    type(body_mode_type), intent(inout) :: mode
    type(mode_work_type), intent(inout) :: work
    integer :: i
    allocate(mode%active(n_rows), mode%stuck(n), mode%sgn(n), mode%f_slide(n), mode%group(n), &
      mode%group_mass(0:n), mode%drive(n))
    mode%drive = 0
    mode%active = .false.
    mode%stuck = .false.
    mode%sgn = 0.0_wp
    mode%f_slide = 0.0_wp
    mode%group = [(i, i = 1, n)]
    mode%group_mass = 1.0_wp
    allocate(work%root(0:n), work%first(n + 1), work%member(n), work%first_row(n + 1), work%row(max(n_rows, 1)), &
      work%local(0:n), work%needs_solve(n))
  end subroutine new_mode

  !> Accelerations a under applied forces f in this mode (module header: O(N)).
  pure subroutine acceleration(self, f, a)
    class(body_mode_type), intent(in) :: self
    real(wp), intent(in) :: f(:)
    real(wp), intent(out) :: a(:)
    real(wp) :: load(0:size(f))
    integer :: i
    ! (the groups' loads zeroed by group and a(i) set on either branch: as `load = 0` and
    ! `a(i) = 0` the compiler made two calls to memset of every call, a sixth of its cost at
    ! N = 1 and the stages call it four times a step)
    do i = 1, size(f)
      load(self%group(i)) = 0.0_wp
    end do
    do i = 1, size(f)
      load(self%group(i)) = load(self%group(i)) + (f(i) + self%f_slide(i))
    end do
    do i = 1, size(f)
      if (self%group(i) > 0) then
        a(i) = load(self%group(i)) / self%group_mass(self%group(i))
      else
        a(i) = 0.0_wp
      end if
    end do
  end subroutine acceleration

  !> The accelerations' response da to a change df of the applied forces (friction fixed).
  pure subroutine rate_response(self, df, da)
    class(body_mode_type), intent(in) :: self
    real(wp), intent(in) :: df(:)
    real(wp), intent(out) :: da(:)
    real(wp) :: load(0:size(df))
    integer :: i
    load = 0.0_wp
    do i = 1, size(df)
      load(self%group(i)) = load(self%group(i)) + df(i)
    end do
    do i = 1, size(df)
      da(i) = 0.0_wp
      if (self%group(i) > 0) da(i) = load(self%group(i)) / self%group_mass(self%group(i))
    end do
  end subroutine rate_response

  !> The accelerations a of a geared scene's groups under forces f: each group's coordinate
  !> accelerates at sum s_i f_i / sum m_i s_i^2, body i at s_i times that (a geared scene's
  !> acceleration, with f + f_slide, and rate_response: its callers choose, since a test
  !> here cost every scene's RK4 stage; nbody_step's mode_acceleration).
  pure subroutine geared_response(self, f, a)
    class(body_mode_type), intent(in) :: self
    real(wp), intent(in) :: f(:)
    real(wp), intent(out) :: a(:)
    real(wp) :: load(0:size(f))
    integer :: i
    load = 0.0_wp
    do i = 1, size(f)
      load(self%group(i)) = load(self%group(i)) + self%scale(i) * f(i)
    end do
    do i = 1, size(f)
      a(i) = 0.0_wp
      if (self%group(i) > 0) a(i) = self%scale(i) * (load(self%group(i)) / self%group_mass(self%group(i)))
    end do
  end subroutine geared_response

  !> Whether two modes hold the same rows, stick the same bodies and slide the same ways.
  pure logical function same_mode(a, b)
    type(body_mode_type), intent(in) :: a, b
    same_mode = all(a%active .eqv. b%active) .and. all(a%stuck .eqv. b%stuck) .and. all(a%sgn == b%sgn)
    if (same_mode .and. allocated(a%friction_sgn) .and. allocated(b%friction_sgn)) &
      same_mode = all(a%friction_sgn == b%friction_sgn) .and. all(a%friction_stuck .eqv. b%friction_stuck)
  end function same_mode

  !> The mode at an instant: forces f and their rate df, velocities v, candidate rows (closed,
  !> zero normal velocity); bodies with static friction and no slip at time t (v = V(t),
  !> their belt's speed, 0 without a belt: impact1d_friction_laws) are at rest. status:
  !> mode_solved, else the failing cluster's LCP status (mode is then not a mode).
  subroutine solve_body_mode(scene, work, f, df, v, t, candidate, mode, status)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    real(wp), intent(in) :: f(:), df(:), v(:), t
    logical, intent(in) :: candidate(:)
    type(body_mode_type), intent(inout) :: mode
    integer, intent(out) :: status
    integer :: i, c
    status = mode_solved
    mode%active = .false.
    do i = 1, scene%n_bodies
      ! A body alone: stuck never (a body at rest is in a cluster of its own), sliding on its slip.
      mode%stuck(i) = .false.
      mode%sgn(i) = 0.0_wp
      if (slip(scene, i, v(i), t) /= 0.0_wp .and. scene%body_friction(i) > 0.0_wp) &
        mode%sgn(i) = sign(1.0_wp, slip(scene, i, v(i), t))
    end do
    if (scene%n_frictions > 0) call friction_directions(scene, work, v, mode)
    call partition(scene, work, v, t, candidate)
    do c = 1, scene%n_bodies
      if (.not. work%needs_solve(c)) cycle
      call solve_cluster(scene, work, c, f, df, v, t, mode, status)
      if (status /= mode_solved) return
    end do
    ! A moving body with static friction but no sliding friction (mu = 0 < mus) has a
    ! direction too, as in the deleted two-body engine (its event point's moving_sign): its stop
    ! is watched, where static friction may hold it (its sliding force -0 sgn stays 0).
    do i = 1, scene%n_bodies
      if (mode%sgn(i) == 0.0_wp .and. slip(scene, i, v(i), t) /= 0.0_wp .and. scene%body_static(i) > 0.0_wp) &
        mode%sgn(i) = sign(1.0_wp, slip(scene, i, v(i), t))
    end do
    call set_groups(scene, mode, work%root)
  end subroutine solve_body_mode

  !> The friction contacts' sliding directions (the sign of their relative velocity; 0 at
  !> relative rest, which the cluster solve decides) and the force of those that slide on
  !> each body (work%pair_force, which the cluster solves add to the applied forces).
  subroutine friction_directions(scene, work, v, mode)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    real(wp), intent(in) :: v(:)
    type(body_mode_type), intent(inout) :: mode
    integer :: j
    real(wp) :: u
    if (.not. allocated(mode%friction_sgn)) allocate(mode%friction_sgn(scene%n_frictions), &
      mode%friction_stuck(scene%n_frictions))
    if (.not. allocated(work%pair_force)) allocate(work%pair_force(scene%n_bodies))
    work%pair_force = 0.0_wp
    do j = 1, scene%n_frictions
      u = relative_velocity(scene, j, v)
      mode%friction_stuck(j) = .false.
      mode%friction_sgn(j) = 0.0_wp
      if (u /= 0.0_wp) mode%friction_sgn(j) = sign(1.0_wp, u)
      associate (a => scene%friction_body(1, j), b => scene%friction_body(2, j))
        work%pair_force(b) = work%pair_force(b) - scene%friction_slide(j) * mode%friction_sgn(j)
        work%pair_force(a) = work%pair_force(a) + scene%friction_slide(j) * mode%friction_sgn(j)
      end associate
    end do
  end subroutine friction_directions

  !> Whether friction contact j is at relative rest with static friction (its ends then in
  !> one cluster, its stick the cluster solve's).
  pure logical function resting_pair(scene, j, v)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: v(:)
    resting_pair = relative_velocity(scene, j, v) == 0.0_wp .and. scene%friction_static(j) > 0.0_wp
  end function resting_pair

  !> Friction contact j's relative velocity v_b - v_a (or its acceleration, given a).
  pure real(wp) function relative_velocity(scene, j, v)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: v(:)
    relative_velocity = v(scene%friction_body(2, j)) - v(scene%friction_body(1, j))
  end function relative_velocity

  !> The clusters (module header): bodies joined by candidate rows between bodies, listed by
  !> root (members in body order, rows in row order), and which need a solve (at time t).
  subroutine partition(scene, work, v, t, candidate)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    real(wp), intent(in) :: v(:), t
    logical, intent(in) :: candidate(:)
    integer :: i, k, r, n
    logical :: joined
    n = scene%n_bodies
    work%root(0:n) = [(i, i = 0, n)]
    do k = 1, scene%n_rows
      if (candidate(k) .and. scene%row_body(1, k) > 0) joined = uf_join(work%root, scene%row_body(1, k), &
        scene%row_body(2, k))
    end do
    do k = 1, scene%n_frictions
      if (resting_pair(scene, k, v)) joined = uf_join(work%root, scene%friction_body(1, k), scene%friction_body(2, k))
    end do
    work%needs_solve = .false.
    work%first = 0
    do i = 1, n
      ! Flattened: root(i) is i's root from here on (no finds per look-up below).
      work%root(i) = uf_find(work%root, i)
      r = work%root(i)
      work%first(r + 1) = work%first(r + 1) + 1
      if (scene%body_static(i) > 0.0_wp .and. slip(scene, i, v(i), t) == 0.0_wp) work%needs_solve(r) = .true.
    end do
    do k = 1, scene%n_frictions
      if (resting_pair(scene, k, v)) work%needs_solve(work%root(scene%friction_body(1, k))) = .true.
    end do
    call bucket(work%first, work%member, work%root(1:n))
    work%first_row = 0
    do k = 1, scene%n_rows
      if (.not. candidate(k)) cycle
      r = work%root(scene%row_body(2, k))
      work%first_row(r + 1) = work%first_row(r + 1) + 1
      work%needs_solve(r) = .true.
    end do
    call bucket(work%first_row, work%row, [(merge(work%root(scene%row_body(2, k)), 0, candidate(k)), &
      k = 1, scene%n_rows)])
  end subroutine partition

  !> Counting sort: list(first(c) : first(c+1) - 1) are the items j (in order) of key(j) = c
  !> (keys 1..N, 0 skipped); on entry first(c + 1) holds key c's count, first(1) anything.
  pure subroutine bucket(first, list, key)
    integer, intent(inout) :: first(:), list(:)
    integer, intent(in) :: key(:)
    integer :: j, c, fill(size(first))
    first(1) = 1
    do c = 2, size(first)
      first(c) = first(c - 1) + first(c)
    end do
    fill = first
    do j = 1, size(key)
      if (key(j) == 0) cycle
      list(fill(key(j))) = j
      fill(key(j)) = fill(key(j)) + 1
    end do
  end subroutine bucket

  !> Cluster c (its root) gathered into a problem of its own at time t, solved, and its mode
  !> scattered.
  subroutine solve_cluster(scene, work, c, f, df, v, t, mode, status)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: c
    real(wp), intent(in) :: f(:), df(:), v(:), t
    type(body_mode_type), intent(inout) :: mode
    integer, intent(out) :: status
    integer :: nb, nr, j, i, k
    nb = work%first(c + 1) - work%first(c)
    nr = work%first_row(c + 1) - work%first_row(c)
    call mode_reserve(work, nb, nr)
    work%local(0) = 0
    do j = 1, nb
      i = work%member(work%first(c) + j - 1)
      work%local(i) = j
      work%mass(j) = scene%body_mass(i)
      work%force(j) = f(i)
      work%rate(j) = df(i)
      ! Friction acts on the slip (impact1d_friction_laws), with its bound there.
      work%friction(j) = sliding_bound(scene, i, slip(scene, i, v(i), t))
      work%static(j) = scene%body_static(i)
      work%velocity(j) = slip(scene, i, v(i), t)
    end do
    do j = 1, nr
      k = work%row(work%first_row(c) + j - 1)
      ! Element by element: a vector subscript here made a temporary (malloc, free) per row,
      ! and a section a call of memcpy per row.
      work%row_body(1, j) = work%local(scene%row_body(1, k))
      work%row_body(2, j) = work%local(scene%row_body(2, k))
      work%row_normal(1, j) = scene%row_normal(1, k)
      work%row_normal(2, j) = scene%row_normal(2, k)
    end do
    if (scene%n_frictions > 0) call gather_pairs(scene, work, c, nb, nr, v)
    if (allocated(work%cluster)) work%cluster%biased = .false.
    if (scene%belt_moves) call gather_belt_frames(scene, work, c, nb, nr, v, t)
    call gathered_mode(work, nb, nr, status)
    if (status /= cluster_solved) return
    do j = 1, nb
      i = work%member(work%first(c) + j - 1)
      mode%stuck(i) = work%stuck(j)
      mode%sgn(i) = work%sgn(j)
    end do
    do j = 1, nr
      mode%active(work%row(work%first_row(c) + j - 1)) = work%active(j)
    end do
    if (scene%n_frictions > 0) call scatter_pairs(scene, work, c, v, mode)
  end subroutine solve_cluster

  !> Cluster c's rows between frames that accelerate apart: a body at rest on a belt of sine
  !> speed is solved in its belt's frame (its force shifted by -m V': impact1d_friction_laws'
  !> shift_to_belts), so a row's acceleration n.a is n.a' + n.b, b_i = V_i'(t) for such a
  !> body, else 0 (the dense solve's row_bias; a wall, or a body in another frame, stays
  !> where it is while the belt carries its neighbour on). O(rows) per such cluster.
  subroutine gather_belt_frames(scene, work, c, nb, nr, v, t)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: c, nb, nr
    real(wp), intent(in) :: v(:), t
    integer :: j, k, e, i
    call dense_reserve(work, nb, nr, 0)
    do j = 1, nr
      k = work%row(work%first_row(c) + j - 1)
      work%cluster%row_bias(j) = 0.0_wp
      work%cluster%row_bias_rate(j) = 0.0_wp
      do e = 1, 2
        i = scene%row_body(e, k)
        if (i == 0) cycle
        if (.not. belt_moving(scene, i)) cycle
        if (slip(scene, i, v(i), t) /= 0.0_wp) cycle
        work%cluster%row_bias(j) = work%cluster%row_bias(j) + scene%row_normal(e, k) * belt_rate(scene, i, t, 2)
        work%cluster%row_bias_rate(j) = work%cluster%row_bias_rate(j) + scene%row_normal(e, k) * &
          belt_rate(scene, i, t, 3)
      end do
      work%cluster%biased = work%cluster%biased .or. work%cluster%row_bias(j) /= 0.0_wp .or. &
        work%cluster%row_bias_rate(j) /= 0.0_wp
    end do
  end subroutine gather_belt_frames

  !> Cluster c's friction contacts (&friction): the force of those that slide added to
  !> their ends' applied forces, those at relative rest given to the dense solve as boxes
  !> (impact1d_cluster_mode's pair_ inputs; O(nf) per cluster).
  subroutine gather_pairs(scene, work, c, nb, nr, v)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: c, nb, nr
    real(wp), intent(in) :: v(:)
    integer :: j, np
    do j = 1, nb
      work%force(j) = work%force(j) + work%pair_force(work%member(work%first(c) + j - 1))
    end do
    np = 0
    do j = 1, scene%n_frictions
      if (pair_of_cluster(scene, work, j, v, c)) np = np + 1
    end do
    call dense_reserve(work, nb, nr, np)
    work%cluster%n_pairs = 0
    do j = 1, scene%n_frictions
      if (.not. pair_of_cluster(scene, work, j, v, c)) cycle
      work%cluster%n_pairs = work%cluster%n_pairs + 1
      associate (p => work%cluster%n_pairs)
        work%cluster%pair_body(:, p) = work%local(scene%friction_body(:, j))
        work%cluster%pair_static(p) = scene%friction_static(j)
        work%cluster%pair_slide(p) = scene%friction_slide(j)
      end associate
    end do
  end subroutine gather_pairs

  !> Whether friction contact j is at relative rest in cluster c (partition's root).
  logical function pair_of_cluster(scene, work, j, v, c)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: j, c
    real(wp), intent(in) :: v(:)
    pair_of_cluster = resting_pair(scene, j, v)
    if (pair_of_cluster) pair_of_cluster = uf_find(work%root, scene%friction_body(1, j)) == c
  end function pair_of_cluster

  !> Cluster c's friction contacts at relative rest: stuck, or the way they slide off.
  subroutine scatter_pairs(scene, work, c, v, mode)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: c
    real(wp), intent(in) :: v(:)
    type(body_mode_type), intent(inout) :: mode
    integer :: j, p
    p = 0
    do j = 1, scene%n_frictions
      if (.not. pair_of_cluster(scene, work, j, v, c)) cycle
      p = p + 1
      mode%friction_stuck(j) = work%cluster%pair_stuck(p)
      mode%friction_sgn(j) = work%cluster%pair_sgn(p)
    end do
  end subroutine scatter_pairs

  !> The mode of the gathered problem of nb bodies and nr rows, every row a candidate (work's
  !> arrays; out: work%active, stuck, sgn): a path of rows by impact1d_path_mode, in O(nb);
  !> any other cluster by the dense LCP (refused past max_dense_unknowns, a status, not an
  !> allocation the machine cannot make), friction then preferred over held rows.
  subroutine gathered_mode(work, nb, nr, status)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr
    integer, intent(out) :: status
    logical :: paired
    work%candidate(1:nr) = .true.
    ! (a cluster with friction contacts at relative rest takes the dense solve: the path
    ! solve has no boxes on relative coordinates; one with rows between belts' frames too:
    ! it has no row_bias)
    paired = .false.
    if (allocated(work%cluster)) paired = work%cluster%n_pairs > 0 .or. work%cluster%biased
    if (.not. work%dense_only .and. .not. paired) then
      if (path_order(work%path, nb, work%row_body(:, 1:nr), work%row_normal(:, 1:nr))) then
        call path_mode(work%path, work%mass(1:nb), work%force(1:nb), work%rate(1:nb), work%friction(1:nb), &
          work%static(1:nb), work%velocity(1:nb), work%row_body(:, 1:nr), work%row_normal(:, 1:nr), &
          work%acc(1:nb), work%acc_rate(1:nb), work%active(1:nr), work%stuck(1:nb), work%sgn(1:nb))
        status = cluster_solved
        return
      end if
    end if
    status = lcp_too_large
    if (max(nr, 1) + 2 * nb > max_dense_unknowns) return
    call dense_reserve(work, nb, nr, 0)
    call solve_gathered(work, nb, nr, status)
    if (status /= cluster_solved) return
    call prefer_friction(work, nb, nr, status)
  end subroutine gathered_mode

  !> The dense solve's memory for nb bodies, nr rows and np friction contacts at relative
  !> rest, made at its first cluster.
  subroutine dense_reserve(work, nb, nr, np)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr, np
    if (.not. allocated(work%cluster)) allocate(work%cluster)
    call cluster_reserve(work%cluster, nb, max(nr, 1), np)
  end subroutine dense_reserve

  !> The gathered problem of nb bodies and nr rows (work's arrays) solved by cluster_mode.
  subroutine solve_gathered(work, nb, nr, status)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr
    integer, intent(out) :: status
    call cluster_mode(work%cluster, work%mass(1:nb), work%force(1:nb), work%rate(1:nb), work%friction(1:nb), &
      work%static(1:nb), work%velocity(1:nb), work%row_body(:, 1:nr), work%row_normal(:, 1:nr), &
      work%candidate(1:nr), work%acc(1:nb), work%active(1:nr), work%stuck(1:nb), work%sgn(1:nb), &
      work%contact_force(1:nr), work%friction_force(1:nb), status)
  end subroutine solve_gathered

  !> Among the force distributions of a cluster with stuck bodies (statically indeterminate:
  !> a block pressed onto a wall that its static friction can hold), the one that leaves a
  !> held row without load when friction alone keeps the same motion: each held row in turn
  !> is let go, and stays so when the cluster then moves as before, accelerations and their
  !> rates (so that it does not close into the row even at the rate), and its ends stay
  !> joined through the other held rows and stuck bodies (the ground joining its own): a
  !> frictionless body resting on a stuck one keeps its row, which friction does not carry
  !> (the choice of the deleted impact1d_modes, "more bodies stuck, then more contacts held", and of
  !> tests/exact_nbody.py: the least contact force, and a force-free row held while its ends
  !> are not otherwise joined).
  subroutine prefer_friction(work, nb, nr, status)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr
    integer, intent(out) :: status
    real(wp) :: acc(nb), da(nb), sgn(nb), tol_f, tol_rate
    logical :: active(nr), stuck(nb)
    integer :: j
    status = cluster_solved
    if (.not. any(work%stuck(1:nb))) return
    ! The same motion to rounding (impact1d_cluster_mode's zero force and rate).
    tol_f = 1.0e3_wp * epsilon(1.0_wp) * (sum(abs(work%force(1:nb))) + 2.0_wp * sum(work%static(1:nb))) + tiny(1.0_wp)
    tol_rate = 1.0e3_wp * epsilon(1.0_wp) * sum(abs(work%rate(1:nb)))
    do j = 1, nr
      if (.not. work%active(j)) cycle
      acc = work%acc(1:nb)
      da = work%cluster%da(1:nb)
      sgn = work%sgn(1:nb)
      active = work%active(1:nr)
      stuck = work%stuck(1:nb)
      work%candidate(j) = .false.
      call solve_gathered(work, nb, nr, status)
      if (status == cluster_solved .and. all(work%stuck(1:nb) .eqv. stuck) .and. all(work%sgn(1:nb) == sgn) &
          .and. all(abs(work%mass(1:nb) * (work%acc(1:nb) - acc)) <= tol_f) &
          .and. all(abs(work%mass(1:nb) * (work%cluster%da(1:nb) - da)) <= tol_rate)) then
        if (ends_joined(j)) cycle
      end if
      ! Friction cannot carry it alone: the row stays held, the solve as it was.
      work%candidate(j) = .true.
      call solve_gathered(work, nb, nr, status)
      if (status /= cluster_solved) return
    end do

  contains

    !> Whether row j's ends are joined by the held rows and stuck bodies of the last solve.
    logical function ends_joined(j)
      integer, intent(in) :: j
      integer :: root(0:nb), i, k
      logical :: joined
      root = [(i, i = 0, nb)]
      do i = 1, nb
        if (work%stuck(i)) root(i) = 0
      end do
      do k = 1, nr
        if (work%active(k)) joined = uf_join(root, work%row_body(1, k), work%row_body(2, k))
      end do
      ends_joined = uf_find(root, work%row_body(1, j)) == uf_find(root, work%row_body(2, j))
    end function ends_joined
  end subroutine prefer_friction

  !> Room for a cluster of nb bodies and nr rows (grown, never shrunk); the dense solve's
  !> own memory is reserved only when a cluster needs it (gathered_mode).
  subroutine mode_reserve(work, nb, nr)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr
    if (.not. allocated(work%path)) allocate(work%path)
    call path_reserve(work%path, nb)
    if (allocated(work%mass)) then
      if (size(work%mass) >= nb .and. size(work%candidate) >= max(nr, 1)) return
      deallocate(work%mass, work%force, work%rate, work%friction, work%static, work%velocity, work%acc, &
        work%acc_rate, work%sgn, work%friction_force, work%stuck, work%contact_force, work%candidate, &
        work%active, work%row_body, work%row_normal)
    end if
    allocate(work%mass(nb), work%force(nb), work%rate(nb), work%friction(nb), work%static(nb), &
      work%velocity(nb), work%acc(nb), work%acc_rate(nb), work%sgn(nb), work%friction_force(nb), &
      work%stuck(nb), work%contact_force(max(nr, 1)), work%candidate(max(nr, 1)), work%active(max(nr, 1)), &
      work%row_body(2, max(nr, 1)), work%row_normal(2, max(nr, 1)))
  end subroutine mode_reserve

  !> The groups of the mode (module header), their masses and the sliding friction forces.
  subroutine set_groups(scene, mode, root)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(inout) :: mode
    integer, intent(inout) :: root(0:)
    integer :: i, k
    logical :: joined
    root(0:scene%n_bodies) = [(i, i = 0, scene%n_bodies)]
    do i = 1, scene%n_bodies
      if (mode%stuck(i)) root(i) = 0
    end do
    do k = 1, scene%n_rows
      if (mode%active(k)) joined = uf_join(root, scene%row_body(1, k), scene%row_body(2, k))
    end do
    do k = 1, scene%n_frictions
      if (mode%friction_stuck(k)) joined = uf_join(root, scene%friction_body(1, k), scene%friction_body(2, k))
    end do
    mode%group_mass = 0.0_wp
    do i = 1, scene%n_bodies
      mode%group(i) = uf_find(root, i)
      mode%group_mass(mode%group(i)) = mode%group_mass(mode%group(i)) + scene%body_mass(i)
    end do
    if (scene%geared) call gear_groups(scene, mode)
    mode%f_slide = -scene%body_friction * mode%sgn
    ! A friction contact sliding: -F sgn on b, its opposite on a.
    do k = 1, scene%n_frictions
      associate (a => scene%friction_body(1, k), b => scene%friction_body(2, k))
        mode%f_slide(b) = mode%f_slide(b) - scene%friction_slide(k) * mode%friction_sgn(k)
        mode%f_slide(a) = mode%f_slide(a) + scene%friction_slide(k) * mode%friction_sgn(k)
      end associate
    end do
    mode%held = any(mode%active) .or. any(mode%stuck)
    if (scene%n_frictions > 0) mode%held = mode%held .or. any(mode%friction_stuck)
    if (scene%drives%n > 0) call drive_components(scene, mode%active, mode%drive)
  end subroutine set_groups

  !> A geared scene's groups (set_groups' union-find roots in mode%group): each body's scale
  !> s_i from its group's root (s = 1) along the held rows (n_a s_a + n_b s_b = 0), and the
  !> groups' masses sum m_i s_i^2. A group whose held rows close a loop of ratios that do
  !> not multiply to 1 cannot move: it is held still (group 0). Sweeps over the held rows
  !> until nothing grows: O(rows x the longest train) at an event point, geared scenes only.
  pure subroutine gear_groups(scene, mode)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(inout) :: mode
    logical :: known(scene%n_bodies), grew, locked(0:scene%n_bodies)
    integer :: i, k
    real(wp) :: mismatch
    if (.not. allocated(mode%scale)) allocate(mode%scale(scene%n_bodies))
    mode%scale = 1.0_wp
    do i = 1, scene%n_bodies
      known(i) = mode%group(i) == i .or. mode%group(i) == 0
    end do
    grew = .true.
    do while (grew)
      grew = .false.
      do k = 1, scene%n_rows
        if (.not. mode%active(k) .or. scene%row_body(1, k) == 0) cycle
        associate (a => scene%row_body(1, k), b => scene%row_body(2, k), n => scene%row_normal(:, k))
          if (known(a) .eqv. known(b)) cycle
          if (known(a)) then
            mode%scale(b) = -(n(1) / n(2)) * mode%scale(a)
            known(b) = .true.
          else
            mode%scale(a) = -(n(2) / n(1)) * mode%scale(b)
            known(a) = .true.
          end if
          grew = .true.
        end associate
      end do
    end do
    locked = .false.
    do k = 1, scene%n_rows
      if (.not. mode%active(k) .or. scene%row_body(1, k) == 0) cycle
      associate (a => scene%row_body(1, k), b => scene%row_body(2, k), n => scene%row_normal(:, k))
        mismatch = n(1) * mode%scale(a) + n(2) * mode%scale(b)
        if (abs(mismatch) > 16.0_wp * epsilon(1.0_wp) * (abs(n(1) * mode%scale(a)) + abs(mode%scale(b)))) &
          locked(mode%group(a)) = .true.
      end associate
    end do
    mode%group_mass = 0.0_wp
    do i = 1, scene%n_bodies
      if (locked(mode%group(i))) mode%group(i) = 0
      mode%group_mass(mode%group(i)) = mode%group_mass(mode%group(i)) + scene%body_mass(i) * mode%scale(i)**2
    end do
  end subroutine gear_groups

  !> drive(i): the drive of the moving ground that the rows marked (rows) join body i to,
  !> through rows between bodies too; 0 for none (or the still ground).
  pure subroutine drive_components(scene, rows, drive)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: rows(:)
    integer, intent(out) :: drive(:)
    integer :: k
    logical :: grew
    drive = 0
    do k = 1, scene%n_rows
      if (rows(k) .and. scene%row_body(1, k) == 0) drive(scene%row_body(2, k)) = scene%row_drive(k)
    end do
    grew = .true.
    do while (grew)
      grew = .false.
      do k = 1, scene%n_rows
        if (.not. rows(k) .or. scene%row_body(1, k) == 0) cycle
        associate (a => scene%row_body(1, k), b => scene%row_body(2, k))
          if (drive(a) == drive(b)) cycle
          if (drive(a) > 0 .and. drive(b) == 0) then
            drive(b) = drive(a)
            grew = .true.
          else if (drive(b) > 0 .and. drive(a) == 0) then
            drive(a) = drive(b)
            grew = .true.
          end if
        end associate
      end do
    end do
  end subroutine drive_components

  !> a(i) := w_d^(order)(t) of a body held to moving ground d (order 2: the accelerations
  !> after acceleration, whose group 0 is the still ground; order 3: their rate, after
  !> rate_response).
  pure subroutine drive_accelerations(scene, mode, t, order, a)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: t
    integer, intent(in) :: order
    real(wp), intent(inout) :: a(:)
    integer :: i
    do i = 1, scene%n_bodies
      if (mode%drive(i) == 0) cycle
      if (order == 2) then
        a(i) = scene%drives%acceleration(mode%drive(i), t)
      else
        a(i) = scene%drives%jerk(mode%drive(i), t)
      end if
    end do
  end subroutine drive_accelerations

  !> The forces f and their rate df as seen from the moving ground that the candidate rows
  !> join each body to (the inertial force -m w'' and its rate added): solved so, a cluster
  !> pressed onto a moving ground is the cluster on a still one (the rows' acceleration
  !> constraint n . a >= -n_ground w'' becomes n . a' >= 0). Bodies on no moving ground are
  !> left as they are. Friction of a body at rest on a moving cluster is not relative to it.
  pure subroutine shift_to_drives(scene, t, candidate, f, df)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t
    logical, intent(in) :: candidate(:)
    real(wp), intent(inout) :: f(:), df(:)
    integer :: drive(scene%n_bodies), i
    call drive_components(scene, candidate, drive)
    do i = 1, scene%n_bodies
      if (drive(i) == 0) cycle
      f(i) = f(i) - scene%body_mass(i) * scene%drives%acceleration(drive(i), t)
      df(i) = df(i) - scene%body_mass(i) * scene%drives%jerk(drive(i), t)
    end do
  end subroutine shift_to_drives
end module impact1d_body_mode
