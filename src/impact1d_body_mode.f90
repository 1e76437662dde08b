!> The contact and friction mode of N bodies (docs/method.md section 9): which rows are held
!> closed, which bodies stick, which way sliding friction acts, and the accelerations within
!> the mode. The N-body engine's counterpart of impact1d_modes (whose kernel enumerates the
!> modes of two bodies).
!>
!> At an event point the bodies fall into clusters joined by candidate rows (closed, zero
!> normal velocity) between bodies; each cluster with a candidate row or a body at rest with
!> friction is one complementarity problem, solved by impact1d_cluster_mode (Lemke's method:
!> no enumeration of 3^N modes); a body alone and sliding needs none. Work is O(N + rows) to
!> partition plus the clusters' own solves.
!>
!> Within a mode every row is of the form (-1, 1), (1, -1) or a wall, so held rows make their
!> ends move as one: the bodies fall into groups (union-find over held rows and stuck bodies,
!> 0 the ground). A group joined to the ground or to a stuck body has a = 0; any other moves
!> with a = (sum of f_i + f_slide_i) / (sum of m_i), its contact forces internal. That is
!> O(N) per stage, whatever the clusters.
module impact1d_body_mode
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_clusters, only: uf_join, uf_find
  use impact1d_cluster_mode, only: cluster_work_type, cluster_reserve, cluster_mode, cluster_solved
  use impact1d_lcp, only: lcp_too_large
  implicit none
  private
  public :: body_mode_type, mode_work_type, new_mode, solve_body_mode, same_mode, mode_solved

  integer, parameter :: mode_solved = cluster_solved   !< otherwise an impact1d_lcp status
  !> The largest cluster problem solved (rows + 2 bodies' unknowns): its dense matrices take
  !> about 24 n^2 bytes, 2.4 GB here (issue 20: a factored solve for chains lifts this).
  integer, parameter, public :: max_dense_unknowns = 10000

  type :: body_mode_type
    logical, allocatable :: active(:)        !< (nr) rows held closed
    logical, allocatable :: stuck(:)         !< (N) bodies held by static friction
    real(wp), allocatable :: sgn(:)          !< (N) sliding direction: friction is -c_i sgn_i
    real(wp), allocatable :: f_slide(:)      !< (N) the sliding friction forces -c_i sgn_i
    integer, allocatable :: group(:)         !< (N) the body's group (a union-find root); 0: held still
    real(wp), allocatable :: group_mass(:)   !< (0:N) mass of the group rooted at each index
    !> Some row is held or some body stuck: conditions that forces can break.
    logical :: held = .false.
  contains
    procedure :: acceleration
    procedure :: rate_response
  end type body_mode_type

  !> The mode solve's memory, sized by the run (new_mode) and grown at event points only when
  !> a cluster is larger than any before.
  type :: mode_work_type
    type(cluster_work_type) :: cluster
    integer, allocatable :: root(:)                  !< (0:N) union-find
    integer, allocatable :: first(:), member(:)      !< (N+1), (N) bodies of each cluster, by root
    integer, allocatable :: first_row(:), row(:)     !< (N+1), (nr) candidate rows of each cluster
    integer, allocatable :: local(:)                 !< (0:N) a body's index in its cluster, 0 the ground
    logical, allocatable :: needs_solve(:)           !< (N) by root: a candidate row or a body at rest
    ! One cluster's problem, gathered (size: the largest cluster so far).
    real(wp), allocatable, dimension(:) :: mass, force, rate, friction, static, velocity, acc, sgn, &
      contact_force, friction_force
    logical, allocatable :: candidate(:), active(:), stuck(:)
    integer, allocatable :: row_body(:, :)
    real(wp), allocatable :: row_normal(:, :)
  end type mode_work_type

contains

  !> A mode of n bodies and n_rows rows with nothing held (each body alone, no friction),
  !> and the work of its solves.
  subroutine new_mode(n, n_rows, mode, work)
    integer, intent(in) :: n, n_rows
    type(body_mode_type), intent(out) :: mode
    type(mode_work_type), intent(out) :: work
    integer :: i
    allocate(mode%active(n_rows), mode%stuck(n), mode%sgn(n), mode%f_slide(n), mode%group(n), &
      mode%group_mass(0:n))
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
    load = 0.0_wp
    do i = 1, size(f)
      load(self%group(i)) = load(self%group(i)) + (f(i) + self%f_slide(i))
    end do
    do i = 1, size(f)
      a(i) = 0.0_wp
      if (self%group(i) > 0) a(i) = load(self%group(i)) / self%group_mass(self%group(i))
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

  !> Whether two modes hold the same rows, stick the same bodies and slide the same ways.
  pure logical function same_mode(a, b)
    type(body_mode_type), intent(in) :: a, b
    same_mode = all(a%active .eqv. b%active) .and. all(a%stuck .eqv. b%stuck) .and. all(a%sgn == b%sgn)
  end function same_mode

  !> The mode at an instant: forces f and their rate df, velocities v, candidate rows (closed,
  !> zero normal velocity); bodies with static friction and v = 0 are at rest. status:
  !> mode_solved, else the failing cluster's LCP status (mode is then not a mode).
  subroutine solve_body_mode(scene, work, f, df, v, candidate, mode, status)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    real(wp), intent(in) :: f(:), df(:), v(:)
    logical, intent(in) :: candidate(:)
    type(body_mode_type), intent(inout) :: mode
    integer, intent(out) :: status
    integer :: i, c
    status = mode_solved
    mode%active = .false.
    do i = 1, scene%n_bodies
      ! A body alone: stuck never (a body at rest is in a cluster of its own), sliding on v.
      mode%stuck(i) = .false.
      mode%sgn(i) = 0.0_wp
      if (v(i) /= 0.0_wp .and. scene%body_friction(i) > 0.0_wp) mode%sgn(i) = sign(1.0_wp, v(i))
    end do
    call partition(scene, work, v, candidate)
    do c = 1, scene%n_bodies
      if (.not. work%needs_solve(c)) cycle
      call solve_cluster(scene, work, c, f, df, v, mode, status)
      if (status /= mode_solved) return
    end do
    ! A moving body with static friction but no sliding friction (mu = 0 < mus) has a
    ! direction too, as in the two-body engine (impact1d_event_point's moving_sign): its stop
    ! is watched, where static friction may hold it (its sliding force -0 sgn stays 0).
    do i = 1, scene%n_bodies
      if (mode%sgn(i) == 0.0_wp .and. v(i) /= 0.0_wp .and. scene%body_static(i) > 0.0_wp) &
        mode%sgn(i) = sign(1.0_wp, v(i))
    end do
    call set_groups(scene, mode, work%root)
  end subroutine solve_body_mode

  !> The clusters (module header): bodies joined by candidate rows between bodies, listed by
  !> root (members in body order, rows in row order), and which need a solve.
  subroutine partition(scene, work, v, candidate)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    real(wp), intent(in) :: v(:)
    logical, intent(in) :: candidate(:)
    integer :: i, k, r, n
    logical :: joined
    n = scene%n_bodies
    work%root(0:n) = [(i, i = 0, n)]
    do k = 1, scene%n_rows
      if (candidate(k) .and. scene%row_body(1, k) > 0) joined = uf_join(work%root, scene%row_body(1, k), &
        scene%row_body(2, k))
    end do
    work%needs_solve = .false.
    work%first = 0
    do i = 1, n
      r = uf_find(work%root, i)
      work%first(r + 1) = work%first(r + 1) + 1
      if (scene%body_static(i) > 0.0_wp .and. v(i) == 0.0_wp) work%needs_solve(r) = .true.
    end do
    call bucket(work%first, work%member, [(uf_find(work%root, i), i = 1, n)])
    work%first_row = 0
    do k = 1, scene%n_rows
      if (.not. candidate(k)) cycle
      r = uf_find(work%root, scene%row_body(2, k))
      work%first_row(r + 1) = work%first_row(r + 1) + 1
      work%needs_solve(r) = .true.
    end do
    call bucket(work%first_row, work%row, [(merge(uf_find(work%root, scene%row_body(2, k)), 0, candidate(k)), &
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

  !> Cluster c (its root) gathered into a problem of its own, solved, and its mode scattered.
  subroutine solve_cluster(scene, work, c, f, df, v, mode, status)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: c
    real(wp), intent(in) :: f(:), df(:), v(:)
    type(body_mode_type), intent(inout) :: mode
    integer, intent(out) :: status
    integer :: nb, nr, j, i, k
    nb = work%first(c + 1) - work%first(c)
    nr = work%first_row(c + 1) - work%first_row(c)
    ! The solve is dense: a cluster past max_dense_unknowns (a long train with every coupler
    ! closed) is refused with a status, not an allocation the machine cannot make.
    status = lcp_too_large
    if (max(nr, 1) + 2 * nb > max_dense_unknowns) return
    call reserve(work, nb, nr)
    work%local(0) = 0
    do j = 1, nb
      i = work%member(work%first(c) + j - 1)
      work%local(i) = j
      work%mass(j) = scene%body_mass(i)
      work%force(j) = f(i)
      work%rate(j) = df(i)
      work%friction(j) = scene%body_friction(i)
      work%static(j) = scene%body_static(i)
      work%velocity(j) = v(i)
    end do
    do j = 1, nr
      k = work%row(work%first_row(c) + j - 1)
      work%row_body(:, j) = work%local(scene%row_body(:, k))
      work%row_normal(:, j) = scene%row_normal(:, k)
    end do
    work%candidate(1:nr) = .true.
    call solve_gathered(work, nb, nr, status)
    if (status /= cluster_solved) return
    call prefer_friction(work, nb, nr, status)
    if (status /= cluster_solved) return
    do j = 1, nb
      i = work%member(work%first(c) + j - 1)
      mode%stuck(i) = work%stuck(j)
      mode%sgn(i) = work%sgn(j)
    end do
    do j = 1, nr
      mode%active(work%row(work%first_row(c) + j - 1)) = work%active(j)
    end do
  end subroutine solve_cluster

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
  !> is let go, and stays so when the cluster then moves as before without closing into it
  !> and its ends stay joined through the other held rows and stuck bodies (the ground
  !> joining its own): a frictionless body resting on a stuck one keeps its row, which
  !> friction does not carry (the choice of impact1d_modes, "more bodies stuck, then more
  !> contacts held", and of tests/exact_nbody.py: the least contact force, and a force-free
  !> row held while its ends are not otherwise joined).
  subroutine prefer_friction(work, nb, nr, status)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr
    integer, intent(out) :: status
    real(wp) :: acc(nb), sgn(nb), rate
    logical :: active(nr), stuck(nb)
    integer :: j, e
    status = cluster_solved
    if (.not. any(work%stuck(1:nb))) return
    do j = 1, nr
      if (.not. work%active(j)) cycle
      acc = work%acc(1:nb)
      sgn = work%sgn(1:nb)
      active = work%active(1:nr)
      stuck = work%stuck(1:nb)
      work%candidate(j) = .false.
      call solve_gathered(work, nb, nr, status)
      rate = 0.0_wp
      do e = 1, 2
        if (work%row_body(e, j) > 0) rate = rate + work%row_normal(e, j) * work%acc(work%row_body(e, j))
      end do
      if (status == cluster_solved .and. all(work%acc(1:nb) == acc) .and. all(work%stuck(1:nb) .eqv. stuck) &
          .and. all(work%sgn(1:nb) == sgn) .and. rate >= 0.0_wp) then
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

  !> Room for a cluster of nb bodies and nr rows (grown, never shrunk).
  subroutine reserve(work, nb, nr)
    type(mode_work_type), intent(inout) :: work
    integer, intent(in) :: nb, nr
    if (allocated(work%mass)) then
      if (size(work%mass) >= nb .and. size(work%candidate) >= max(nr, 1)) return
      deallocate(work%mass, work%force, work%rate, work%friction, work%static, work%velocity, work%acc, &
        work%sgn, work%friction_force, work%stuck, work%contact_force, work%candidate, work%active, &
        work%row_body, work%row_normal)
    end if
    allocate(work%mass(nb), work%force(nb), work%rate(nb), work%friction(nb), work%static(nb), &
      work%velocity(nb), work%acc(nb), work%sgn(nb), work%friction_force(nb), work%stuck(nb), &
      work%contact_force(max(nr, 1)), work%candidate(max(nr, 1)), work%active(max(nr, 1)), &
      work%row_body(2, max(nr, 1)), work%row_normal(2, max(nr, 1)))
    call cluster_reserve(work%cluster, nb, max(nr, 1))
  end subroutine reserve

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
    mode%group_mass = 0.0_wp
    do i = 1, scene%n_bodies
      mode%group(i) = uf_find(root, i)
      mode%group_mass(mode%group(i)) = mode%group_mass(mode%group(i)) + scene%body_mass(i)
    end do
    mode%f_slide = -scene%body_friction * mode%sgn
    mode%held = any(mode%active) .or. any(mode%stuck)
  end subroutine set_groups
end module impact1d_body_mode
