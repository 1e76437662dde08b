!> Clusters: the connected sets of bodies under closed body-body rows (issue 19, stage 4;
!> docs/nbody-plan.md section 5, "Clusters"). A cluster is the unit of the mode solve and of
!> a joint impact; a wall is the ground and never joins bodies. The N-body event point uses
!> clusters_build's incidence lists (row_start, row_list) and the search's queue and marks to
!> find what an event touches (impact1d_nbody_event); clusters_close / clusters_open are not
!> called yet.
!>
!> What it guarantees:
!> - After any sequence of clusters_close / clusters_open, cluster_of(i) = cluster_of(j) exactly
!>   when bodies i and j are connected by closed body-body rows; each cluster's members are
!>   the list first(c), next(first(c)), ... (0 ends it), of length size(c); ids are 1..N,
!>   the unused ones kept for reuse.
!> - The cost is in the cluster, not in N: a closing row between two clusters relabels the
!>   smaller one (O(its size)); a releasing row searches (breadth first, over the incidence
!>   lists) the cluster it was in, from one end, and relabels what it reaches if the other
!>   end is not among it (O(cluster size + its rows)). Nothing is allocated after
!>   clusters_build.
!> Also here, shared by the cluster kernels: the union-find (uf_join, uf_find) and group mean
!> (group_means) of their exact common accelerations and velocities, and the rows' algebra
!> (row_rate: n_k . u; row_coupling: n_k M^-1 n_l over a selection of rows).
module impact1d_clusters
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: cluster_set_type, clusters_build, clusters_close, clusters_open
  public :: uf_join, uf_find, group_means, row_coupling, row_rate, row_closed

  type :: cluster_set_type
    integer :: n_bodies = 0, n_rows = 0
    integer, allocatable :: row_body(:, :)     !< (2, nr) ends a, b (0 = ground)
    logical, allocatable :: closed(:)          !< (nr) the row is closed
    integer, allocatable :: row_start(:)       !< (N + 1) CSR: the rows on body i are
    integer, allocatable :: row_list(:)        !< (2 nr)  row_list(row_start(i):row_start(i + 1) - 1)
    integer, allocatable :: cluster_of(:)      !< (N) cluster id of body i
    integer, allocatable :: first(:)           !< (N) first member of cluster c (0: id unused)
    integer, allocatable :: next(:)            !< (N) next member after body i (0: last)
    integer, allocatable :: size(:)            !< (N) members of cluster c
    integer, allocatable :: free(:)            !< (N) unused ids, a stack of n_free
    integer :: n_free = 0
    integer, allocatable :: queue(:), mark(:)  !< (N) breadth-first search: queue, visit stamps
    integer :: stamp = 0
  end type cluster_set_type

contains

  !> Every body its own cluster, every row open; the incidence lists of the rows (once per run).
  subroutine clusters_build(set, n_bodies, row_body)
    type(cluster_set_type), intent(out) :: set
    integer, intent(in) :: n_bodies, row_body(:, :)
    integer :: i, k, e, nr
    nr = size(row_body, 2)
    set%n_bodies = n_bodies
    set%n_rows = nr
    allocate(set%row_body(2, nr), set%closed(nr), set%row_start(n_bodies + 1), set%row_list(2 * nr), &
      set%cluster_of(n_bodies), set%first(n_bodies), set%next(n_bodies), set%size(n_bodies), &
      set%free(n_bodies), set%queue(n_bodies), set%mark(n_bodies))
    set%row_body = row_body
    set%closed = .false.
    ! CSR: counts in row_start(i + 1), prefix sums to starts, a fill that advances row_start(i)
    ! to i + 1's start, then the starts shifted back.
    set%row_start = 0
    do k = 1, nr
      do e = 1, 2
        i = row_body(e, k)
        if (i > 0) set%row_start(i + 1) = set%row_start(i + 1) + 1
      end do
    end do
    set%row_start(1) = 1
    do i = 1, n_bodies
      set%row_start(i + 1) = set%row_start(i + 1) + set%row_start(i)
    end do
    do k = 1, nr
      do e = 1, 2
        i = row_body(e, k)
        if (i == 0) cycle
        set%row_list(set%row_start(i)) = k
        set%row_start(i) = set%row_start(i) + 1
      end do
    end do
    do i = n_bodies, 1, -1
      set%row_start(i + 1) = set%row_start(i)
    end do
    set%row_start(1) = 1
    do i = 1, n_bodies
      set%cluster_of(i) = i
      set%first(i) = i
      set%next(i) = 0
      set%size(i) = 1
    end do
    set%n_free = 0
    set%mark = 0
    set%stamp = 0
  end subroutine clusters_build

  !> Row k closes: if it joins two bodies of different clusters, the smaller one joins the
  !> larger (its id is freed).
  subroutine clusters_close(set, k)
    type(cluster_set_type), intent(inout) :: set
    integer, intent(in) :: k
    integer :: big, small, i, last
    set%closed(k) = .true.
    if (any(set%row_body(:, k) == 0)) return
    big = set%cluster_of(set%row_body(1, k))
    small = set%cluster_of(set%row_body(2, k))
    if (big == small) return
    if (set%size(small) > set%size(big)) then
      i = big
      big = small
      small = i
    end if
    i = set%first(small)
    last = i
    do while (i /= 0)
      set%cluster_of(i) = big
      last = i
      i = set%next(i)
    end do
    set%next(last) = set%first(big)
    set%first(big) = set%first(small)
    set%size(big) = set%size(big) + set%size(small)
    set%first(small) = 0
    set%size(small) = 0
    set%n_free = set%n_free + 1
    set%free(set%n_free) = small
  end subroutine clusters_close

  !> Row k releases: if its ends no longer connect, the part reached from end a becomes a
  !> new cluster.
  subroutine clusters_open(set, k)
    type(cluster_set_type), intent(inout) :: set
    integer, intent(in) :: k
    integer :: a, b, old, c, n_reached
    set%closed(k) = .false.
    a = set%row_body(1, k)
    b = set%row_body(2, k)
    if (a == 0 .or. b == 0) return
    call reach(set, a, b, n_reached)
    if (set%mark(b) == set%stamp) return            ! still connected
    old = set%cluster_of(a)
    c = set%free(set%n_free)
    set%n_free = set%n_free - 1
    call relabel(set, old, c, n_reached)
  end subroutine clusters_open

  !> Breadth-first search from body a over closed body-body rows, stopping early when b is
  !> reached; the bodies reached are queue(1:n_reached), marked with the new stamp.
  subroutine reach(set, a, b, n_reached)
    type(cluster_set_type), intent(inout) :: set
    integer, intent(in) :: a, b
    integer, intent(out) :: n_reached
    integer :: head, i, j, p, k
    set%stamp = set%stamp + 1
    set%mark(a) = set%stamp
    set%queue(1) = a
    n_reached = 1
    head = 0
    do while (head < n_reached)
      head = head + 1
      i = set%queue(head)
      do p = set%row_start(i), set%row_start(i + 1) - 1
        k = set%row_list(p)
        if (.not. set%closed(k) .or. any(set%row_body(:, k) == 0)) cycle
        j = sum(set%row_body(:, k)) - i              ! the other end
        if (set%mark(j) == set%stamp) cycle
        set%mark(j) = set%stamp
        n_reached = n_reached + 1
        set%queue(n_reached) = j
        if (j == b) return
      end do
    end do
  end subroutine reach

  !> The bodies reached (queue(1:n_reached), marked) leave cluster old for the new id c;
  !> old's member list keeps the others, in their order.
  subroutine relabel(set, old, c, n_reached)
    type(cluster_set_type), intent(inout) :: set
    integer, intent(in) :: old, c, n_reached
    integer :: i, p, kept_last, i_next
    kept_last = 0
    i = set%first(old)
    set%first(old) = 0
    do while (i /= 0)
      i_next = set%next(i)
      set%next(i) = 0
      if (set%mark(i) /= set%stamp) then
        if (kept_last == 0) then
          set%first(old) = i
        else
          set%next(kept_last) = i
        end if
        kept_last = i
      end if
      i = i_next
    end do
    set%first(c) = 0
    do p = n_reached, 1, -1
      i = set%queue(p)
      set%cluster_of(i) = c
      set%next(i) = set%first(c)
      set%first(c) = i
    end do
    set%size(c) = n_reached
    set%size(old) = set%size(old) - n_reached
  end subroutine relabel

  !> Join a and b (0 = the ground, always a root) in the union-find root(0:): .false. if they
  !> were joined already.
  logical function uf_join(root, a, b) result(joined)
    integer, intent(inout) :: root(0:)
    integer, intent(in) :: a, b
    integer :: ra, rb
    ra = uf_find(root, a)
    rb = uf_find(root, b)
    joined = ra /= rb
    if (joined) root(max(ra, rb)) = min(ra, rb)
  end function uf_join

  !> The root of i (path halving).
  integer function uf_find(root, i) result(r)
    integer, intent(inout) :: root(0:)
    integer, intent(in) :: i
    r = i
    do while (root(r) /= r)
      root(r) = root(root(r))
      r = root(r)
    end do
  end function uf_find

  !> Each union-find group of bodies 1..size(mass) gets one value: 0 if joined to the ground,
  !> else the mass-weighted mean of x over the group (a momentum over a mass, for
  !> velocities). A body alone keeps its own. group_mass, group_sum: scratch (0:N).
  subroutine group_means(root, mass, x, group_mass, group_sum)
    integer, intent(inout) :: root(0:)
    real(wp), intent(in) :: mass(:)
    real(wp), intent(inout) :: x(:), group_mass(0:), group_sum(0:)
    integer :: i, r
    group_mass(0:size(mass)) = 0.0_wp
    group_sum(0:size(mass)) = 0.0_wp
    do i = 1, size(mass)
      r = uf_find(root, i)
      group_mass(r) = group_mass(r) + mass(i)
      group_sum(r) = group_sum(r) + mass(i) * x(i)
    end do
    do i = 1, size(mass)
      r = uf_find(root, i)
      if (r == 0) then
        x(i) = 0.0_wp
      else if (group_mass(r) /= mass(i)) then
        x(i) = group_sum(r) / group_mass(r)
      end if
    end do
  end subroutine group_means

  !> n_k . u for row k (ends row_body(:, k), 0 the ground, which does not move).
  pure real(wp) function row_rate(row_body, row_normal, k, u) result(rate)
    integer, intent(in) :: row_body(:, :), k
    real(wp), intent(in) :: row_normal(:, :), u(:)
    integer :: e
    rate = 0.0_wp
    do e = 1, 2
      if (row_body(e, k) > 0) rate = rate + row_normal(e, k) * u(row_body(e, k))
    end do
  end function row_rate

  !> Row k closed and staying closed under accelerations a with rates da: n.a and n.da zero
  !> within the zero force tol_f and rate tol_rate through the row's ends' inverse masses.
  !> bias, bias_rate: added to n.a and n.da (ends solved in accelerating frames:
  !> impact1d_cluster_mode's row_bias).
  pure logical function row_closed(row_body, row_normal, k, mass, a, da, tol_f, tol_rate, bias, bias_rate) &
      result(closed)
    integer, intent(in) :: row_body(:, :), k
    real(wp), intent(in) :: row_normal(:, :), mass(:), a(:), da(:), tol_f, tol_rate
    real(wp), intent(in), optional :: bias, bias_rate
    real(wp) :: inverse_mass, shift, shift_rate
    integer :: e
    inverse_mass = 0.0_wp
    do e = 1, 2
      if (row_body(e, k) > 0) inverse_mass = inverse_mass + abs(row_normal(e, k)) / mass(row_body(e, k))
    end do
    shift = 0.0_wp
    shift_rate = 0.0_wp
    if (present(bias)) shift = bias
    if (present(bias_rate)) shift_rate = bias_rate
    closed = abs(row_rate(row_body, row_normal, k, a) + shift) <= 2.0_wp * tol_f * inverse_mass .and. &
      abs(row_rate(row_body, row_normal, k, da) + shift_rate) <= 2.0_wp * tol_rate * inverse_mass
  end function row_closed

  !> The selected rows numbered 1..n_selected in row order (row_var(k), 0 for the others) and
  !> their coupling through the bodies, coupling(p, q) = n_p M^-1 n_q (1:n_selected square).
  subroutine row_coupling(mass, row_body, row_normal, selected, row_var, n_selected, coupling)
    real(wp), intent(in) :: mass(:), row_normal(:, :)
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: selected(:)
    integer, intent(out) :: row_var(:), n_selected
    real(wp), intent(inout) :: coupling(:, :)
    integer :: k, l, e, f, i
    n_selected = 0
    do k = 1, size(selected)
      row_var(k) = 0
      if (.not. selected(k)) cycle
      n_selected = n_selected + 1
      row_var(k) = n_selected
    end do
    coupling(1:n_selected, 1:n_selected) = 0.0_wp
    do k = 1, size(selected)
      if (row_var(k) == 0) cycle
      do e = 1, 2
        i = row_body(e, k)
        if (i == 0) cycle
        do l = 1, size(selected)
          if (row_var(l) == 0) cycle
          do f = 1, 2
            if (row_body(f, l) == i) coupling(row_var(k), row_var(l)) = coupling(row_var(k), row_var(l)) + &
              row_normal(e, k) * row_normal(f, l) / mass(i)
          end do
        end do
      end do
    end do
  end subroutine row_coupling
end module impact1d_clusters
